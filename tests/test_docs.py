"""The documentation is current and its examples run."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from lagsym.cli import COMMANDS, command_module

from conftest import EXAMPLES, ROOT, example_files as _files, need_opengl, run_example
from systempackages import can_render

sys.path.insert(0, str(ROOT / "docs"))
import gen_cli  # noqa: E402

# Examples that name a real serial device or a shop's network serial server show how to reach a
# machine; they cannot run here and are not collected.  Every other example runs.
MACHINE_PORTS = ("/dev/", "socket://", "rfc2217://")


def _examples():
    out = []
    for name in COMMANDS:
        text = getattr(command_module(name), "DESCRIPTION", "")
        if "examples:" not in text:
            continue
        block = text.split("examples:", 1)[1].replace("\\\n", " ")
        for line in block.splitlines():
            line = line.strip()
            if line.startswith("lagsym ") and not any(p in line for p in MACHINE_PORTS):
                out.append((name, line))
    return out


def test_cli_reference_is_current():
    assert (ROOT / "docs" / "cli.md").read_text() == gen_cli.page(), "run: python3 docs/gen_cli.py"


def test_every_command_has_examples():
    for name in COMMANDS:
        text = getattr(command_module(name), "DESCRIPTION", "")
        assert "examples:" in text and "lagsym " + name in text.split("examples:", 1)[1], name
    # All but 'receive' (which waits for a control to punch a program) have one that runs here.
    assert {name for name, _ in _examples()} == set(COMMANDS) - {"receive"}


def _draws(line: str) -> bool:
    return line.startswith("lagsym plot ") or " --plot " in line


def _example_groups() -> dict[str, list[str]]:
    """Each command's examples, after the earlier examples (of any command) that write the files they read."""
    examples = [line for _, line in _examples()]
    files = [_files(line) for line in examples]
    groups: dict[str, set[int]] = {}
    for k, (name, _) in enumerate(_examples()):
        wanted, todo = {k}, [k]
        while todo:
            j = todo.pop()
            for f in files[j][0]:
                makers = [i for i in range(j) if f in files[i][1]]
                if makers and makers[-1] not in wanted:
                    wanted.add(makers[-1])
                    todo.append(makers[-1])
        groups.setdefault(name, set()).update(wanted)
    return {name: [examples[k] for k in sorted(ks)] for name, ks in groups.items()}


def test_each_example_group_holds_what_its_examples_read():
    groups = _example_groups()
    assert set(groups) == {name for name, _ in _examples()}
    verify = groups["verify"]
    assert any(" -o O1000.nc" in line and line.startswith("lagsym toolpath") for line in verify)
    assert any(line.startswith("lagsym job examples/example-4-job.toml") for line in verify)
    assert any(line.startswith("lagsym macro") and "-o O1000.nc" in line for line in groups["simulate"])


@pytest.mark.slow
@pytest.mark.parametrize("command", sorted({name for name, _ in _examples()}))
def test_cli_examples_run(command, tmp_path, monkeypatch, tmp_path_factory):
    """Run every example of a command, in order, in a folder of its own, after the examples of other commands
    that write the files they read (each of those once in the whole run: :func:`run_example`).

    Without an OpenGL the examples that draw are left out and the test skips at the end, naming them
    and the packages to install (the others have run by then)."""
    (tmp_path / "examples").symlink_to(EXAMPLES)
    monkeypatch.chdir(tmp_path)
    can_draw = can_render()
    left_out = []
    for line in _example_groups()[command]:
        if _draws(line) and not can_draw:
            left_out.append(line)
            continue
        run_example(line, tmp_path_factory)
    if left_out:
        need_opengl(f"{len(left_out)} examples that draw ({left_out[0]!r}, ...)")


@pytest.mark.slow
def test_mkdocs_builds_strictly(tmp_path):
    """The site builds with no warning; its tutorial pages are the notebooks with their stored outputs."""
    path = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
    r = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--quiet", "--site-dir", str(tmp_path)],
                       cwd=ROOT, capture_output=True, text=True,
                       env={**os.environ, "NO_MKDOCS_2_WARNING": "1", "PYTHONPATH": path, "LAGSYM_DOCS_EXECUTE": "false"})
    assert r.returncode == 0, r.stderr[-3000:]
    assert (tmp_path / "index.html").exists() and (tmp_path / "api" / "index.html").exists()
    page = (tmp_path / "03-comparison" / "index.html").read_text()
    assert "compare_surfaces" in page  # the tutorial page is the notebook
    # Its printed results and figures are on the page.
    assert "14.0937" in page  # printed by the Figure 11 table cell
    assert page.count("data:image/png;base64,") >= 2  # Figure 10 and Figure 11


def test_tutorials_are_the_notebooks():
    """docs/ links each notebook: one copy of each tutorial."""
    notebooks = sorted((ROOT / "notebooks").glob("*.ipynb"))
    assert len(notebooks) == 6
    for nb in notebooks:
        link = ROOT / "docs" / nb.name
        assert link.is_symlink() and link.resolve() == nb.resolve(), link
    assert not (ROOT / "docs" / "tutorials").exists()
