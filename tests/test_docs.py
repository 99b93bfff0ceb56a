"""The documentation is current and its examples run."""

from __future__ import annotations

import io
import os
import shlex
import subprocess
import sys

import pytest

from lagsym.cli import COMMANDS, command_module, main

from conftest import EXAMPLES, ROOT, need_opengl
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


def _files(line: str) -> tuple[set[str], set[str]]:
    """The files in the working folder an example reads and those it writes (``-o``)."""
    words = shlex.split(line)[2:]
    written = {w for k, w in enumerate(words[1:]) if words[k] in ("-o", "--output")}
    read = {w for w in words if "." in w and "/" not in w and not w.startswith("-") and " " not in w} - written
    return read, written


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


@pytest.fixture(scope="session")
def example_outputs(tmp_path_factory):
    """A folder the whole run shares (every test worker), where each example keeps the files it wrote."""
    base = tmp_path_factory.getbasetemp()
    folder = (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "example-outputs"
    folder.mkdir(exist_ok=True)
    return folder


def _run_example(line: str, shared) -> None:
    """Run an example in the working folder, once in the whole run: an example that writes files and has run
    already (in another command's group, on the same inputs) gives its files again instead of running twice."""
    import fcntl
    import hashlib
    import shutil
    from pathlib import Path

    def run():
        out, err = io.StringIO(), io.StringIO()
        status = main(shlex.split(line)[1:], out, err)
        assert status == 0, f"{line!r} exited {status}: {err.getvalue()}"

    reads, writes = _files(line)
    if not writes or any("/" in name for name in writes):
        return run()
    key = hashlib.sha256(line.encode())
    for name in sorted(reads):
        key.update(name.encode() + b"\0" + (Path(name).read_bytes() if Path(name).is_file() else b""))
    keep = shared / key.hexdigest()[:24]
    keep.mkdir(exist_ok=True)
    with open(keep / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # one worker runs it; the others wait for its files
        if (keep / ".done").exists():
            for name in writes:
                shutil.copyfile(keep / name, name)
            return None
        run()
        for name in writes:
            shutil.copyfile(name, keep / name)
        (keep / ".done").touch()
    return None


@pytest.mark.slow
@pytest.mark.parametrize("command", sorted({name for name, _ in _examples()}))
def test_cli_examples_run(command, tmp_path, monkeypatch, example_outputs):
    """Run every example of a command, in order, in a folder of its own, after the examples of other commands
    that write the files they read (each of those once in the whole run: :func:`_run_example`).

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
        _run_example(line, example_outputs)
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
