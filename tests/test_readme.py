"""The README's Quick start and system packages are what CI runs and installs."""

from __future__ import annotations

import re
import sys

from conftest import ROOT, SYSTEM_PACKAGES

sys.path.insert(0, str(ROOT / ".ci"))
import plain_install  # noqa: E402

README = (ROOT / "README.md").read_text()
CI = (ROOT / ".ci" / "run").read_text()


def test_ci_runs_the_readme_test_command_verbatim():
    first, second = plain_install.quick_start()
    assert "pip install -q . " in first and "[test]" not in first  # a plain install
    assert second in CI.splitlines()
    assert ".ci/plain_install.py" in CI


def test_ci_installs_exactly_the_readme_system_packages():
    section = README.split("### System packages", 1)[1].split("\n## ", 1)[0]
    listed = set()
    for row in re.findall(r"^\| `([^`]+)` \|", section, re.M):
        listed.update(row.split())
    installed = set(re.search(r"apt-get install -y -qq --no-install-recommends ([^>]+)>", CI).group(1).split())
    assert listed == installed
    assert listed == {p for group in SYSTEM_PACKAGES for p in group.split()}


def test_readme_shows_commands_that_ci_runs():
    commands = plain_install.shown_commands()
    assert commands[0] == "lagsym equation examples/paper-example-1.json"
    assert any(c.startswith("lagsym plot ") for c in commands)


def test_the_shell_block_activates_the_environment_first():
    """A fresh shell has no `lagsym` on its PATH: the block says how to get it before using it."""
    lines = plain_install.shell_block()
    assert lines[0] == plain_install.ACTIVATE
    assert all(line.startswith("lagsym ") for line in lines[1:])


def test_the_python_example_runs_and_prints_what_its_comments_say(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    exec(compile(plain_install.python_block(), "README.md", "exec"), {})
    out = capsys.readouterr().out.splitlines()
    assert out == ["x**2 + 3*y", "11.5"]


def test_the_readme_is_a_front_door():
    """Short, with a picture that exists, links that resolve and the licence pyproject names."""
    import tomllib

    lines = README.splitlines()
    assert len(lines) <= 120, len(lines)
    pictures = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", README)
    assert pictures and all((ROOT / p).is_file() for p in pictures)
    for target in re.findall(r"\]\(([^)#]+)\)", README):
        if "://" not in target:
            assert (ROOT / target).exists(), target
    licence = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["license"]["text"]
    assert licence == "MIT" and (ROOT / "LICENSE").read_text().startswith("MIT License")
    assert "-m pytest" in plain_install.quick_start()[1]


def test_the_measured_figures_are_the_results_file():
    """The README's and the benchmarks page's figures are those benchmarks/results.json holds, and no others."""
    import json

    sys.path.insert(0, str(ROOT / "benchmarks"))
    import results

    data = json.loads((ROOT / "benchmarks" / "results.json").read_text())
    assert data, "no benchmark has recorded a result"
    block = README.split(results.BEGIN, 1)[1].split(results.END, 1)[0]
    # Rebuilt here from the file's fields, not by the module that wrote the README.
    want = [f"- {data[k]['task']}: {data[k]['peer']} takes {data[k]['ratio']:g}x as long"
            for k in results.README_KEYS if k in data]
    assert block.strip().splitlines() == want
    page = (ROOT / "docs" / "benchmarks.md").read_text()
    for e in data.values():
        assert f"| {e['task']} | {e['peer']} | {e['ratio']:g}x |" in page and e["date"] in page
    # No other ratio or dated figure in the README's prose.
    prose = README.replace(block, "")
    assert not re.search(r"\d+(\.\d+)?x\b", prose), re.findall(r".{30}\d+(?:\.\d+)?x\b", prose)
    assert not re.search(r"20\d\d-\d\d-\d\d", prose)
