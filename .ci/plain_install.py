"""Run the README's first Quick start command in a fresh clone, then every command the README shows.

Everything in the README must work after the plain install alone (no test extras).  The commands
run in order in the clone (later ones use earlier outputs); those that need a machine on a serial
port are listed and not run.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
NEEDS_A_MACHINE = ("/dev/tty",)


def quick_start() -> list[str]:
    text = (ROOT / "README.md").read_text()
    block = text.split("## Quick start", 1)[1].split("```", 2)[1]
    return [line for line in block.splitlines() if line.strip()]


ACTIVATE = ". .venv/bin/activate"


def shell_block() -> list[str]:
    """The README's first use from the shell: the activation, then the commands, one a line."""
    text = (ROOT / "README.md").read_text()
    block = text.split("## First use from the shell", 1)[1].split("```", 2)[1].replace("\\\n", " ")
    return [line.split("  #")[0].strip() for line in block.splitlines() if line.strip()]


def shown_commands() -> list[str]:
    return [line for line in shell_block() if line.startswith("lagsym ")]


def python_block() -> str:
    """The README's first use from Python."""
    text = (ROOT / "README.md").read_text()
    return text.split("## First use from Python", 1)[1].split("```python", 1)[1].split("```", 1)[0]


WAIT_FOR_BACKGROUND = """
import time
from lagsym.toolpath.kernelcache import compiling_in_background
end = time.monotonic() + 600
while compiling_in_background() and time.monotonic() < end:
    time.sleep(0.5)
"""


def main() -> int:
    with tempfile.TemporaryDirectory(prefix="lagsym-plain-") as tmp:
        clone = Path(tmp) / "lagsym"
        subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
        first = quick_start()[0]
        print(f"plain install: {first}", flush=True)
        subprocess.run(["bash", "-c", first], cwd=clone, check=True)
        # As the README says: activate the environment, then the commands (each in a shell of its own).
        if shell_block()[0] != ACTIVATE:
            print(f"FAILED: the README's shell block starts {shell_block()[0]!r}, not {ACTIVATE!r}")
            return 1
        env = dict(os.environ)
        for command in shown_commands():
            if any(p in command for p in NEEDS_A_MACHINE):
                print(f"not run (needs a machine on a serial port): {command}")
                continue
            print(f"$ {command}", flush=True)
            done = subprocess.run(["bash", "-c", f"{ACTIVATE} && {command}"], cwd=clone, env=env,
                                  capture_output=True, text=True)
            if done.returncode != 0:
                print(done.stdout[-2000:], done.stderr[-2000:], sep="\n")
                print(f"FAILED with exit status {done.returncode} after the plain install: {command}")
                return 1
        print("$ the README's Python example", flush=True)
        done = subprocess.run([str(clone / ".venv" / "bin" / "python"), "-c", python_block()], cwd=clone,
                              capture_output=True, text=True)
        if done.returncode != 0 or "x**2 + 3*y" not in done.stdout:
            print(done.stdout[-2000:], done.stderr[-2000:], sep="\n")
            print("FAILED after the plain install: the README's Python example")
            return 1
        # The first command started the kernels' compile in the background; it writes into the venv until it ends.
        subprocess.run([str(clone / ".venv" / "bin" / "python"), "-c", WAIT_FOR_BACKGROUND], cwd=tmp, check=True)
    print("every README command and the Python example ran after the plain install")
    return 0


if __name__ == "__main__":
    sys.exit(main())
