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


def shown_commands() -> list[str]:
    text = (ROOT / "README.md").read_text()
    block = text.split("## What it does", 1)[1].split("```", 2)[1].replace("\\\n", " ")
    return [line.split("  #")[0].strip() for line in block.splitlines() if line.strip().startswith("lagsym ")]


def main() -> int:
    with tempfile.TemporaryDirectory(prefix="lagsym-plain-") as tmp:
        clone = Path(tmp) / "lagsym"
        subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
        first = quick_start()[0]
        print(f"plain install: {first}", flush=True)
        subprocess.run(["bash", "-c", first], cwd=clone, check=True)
        env = {**os.environ, "PATH": f"{clone / '.venv' / 'bin'}{os.pathsep}{os.environ['PATH']}"}
        for command in shown_commands():
            if any(p in command for p in NEEDS_A_MACHINE):
                print(f"not run (needs a machine on a serial port): {command}")
                continue
            print(f"$ {command}", flush=True)
            done = subprocess.run(["bash", "-c", command], cwd=clone, env=env, capture_output=True, text=True)
            if done.returncode != 0:
                print(done.stdout[-2000:], done.stderr[-2000:], sep="\n")
                print(f"FAILED with exit status {done.returncode} after the plain install: {command}")
                return 1
    print("every README command ran after the plain install")
    return 0


if __name__ == "__main__":
    sys.exit(main())
