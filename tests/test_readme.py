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
