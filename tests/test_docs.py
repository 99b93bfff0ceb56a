"""The documentation is current and its examples run."""

from __future__ import annotations

import io
import os
import shlex
import subprocess
import sys


from lagsym.cli import COMMANDS, command_module, main

from conftest import EXAMPLES, ROOT

sys.path.insert(0, str(ROOT / "docs"))
import gen_cli  # noqa: E402
import gen_tutorials  # noqa: E402

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


def test_tutorials_are_current():
    for path, text in gen_tutorials.pages().items():
        assert path.read_text() == text, f"run: python3 docs/gen_tutorials.py ({path.name})"


def test_every_command_has_examples():
    for name in COMMANDS:
        text = getattr(command_module(name), "DESCRIPTION", "")
        assert "examples:" in text and "lagsym " + name in text.split("examples:", 1)[1], name
    # All but 'receive' (which waits for a control to punch a program) have one that runs here.
    assert {name for name, _ in _examples()} == set(COMMANDS) - {"receive"}


def test_cli_examples_run(tmp_path, monkeypatch):
    """Run every example of every command, in order, in one folder (later ones use earlier outputs)."""
    (tmp_path / "examples").symlink_to(EXAMPLES)
    monkeypatch.chdir(tmp_path)
    for name, line in _examples():
        out, err = io.StringIO(), io.StringIO()
        status = main(shlex.split(line)[1:], out, err)
        assert status == 0, f"{line!r} exited {status}: {err.getvalue()}"


def test_mkdocs_builds_strictly(tmp_path):
    r = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--quiet", "--site-dir", str(tmp_path)],
                       cwd=ROOT, capture_output=True, text=True, env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})
    assert r.returncode == 0, r.stderr[-3000:]
    assert (tmp_path / "index.html").exists() and (tmp_path / "api" / "index.html").exists()
