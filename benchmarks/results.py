"""The benchmarks' headline results: one file, ``benchmarks/results.json``, and the pages made from it.

Each benchmark script ends with :func:`record`: its headline figure, the time
a named peer takes over lagsym's time for the same work in the same run,
with the machine, the date, the load average and the command that measured
it.  Recording into the repository's own file also renders
``docs/benchmarks.md`` and the README's "Measured" lines from it, so prose
never carries a figure of its own; ``tests/test_readme.py`` checks both
against the file.

    python3 benchmarks/results.py            # render docs/benchmarks.md and the README lines again
    python3 benchmarks/results.py --check    # exit 1 if either is not what the file gives
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULTS = HERE / "results.json"
PAGE = ROOT / "docs" / "benchmarks.md"
README = ROOT / "README.md"
BEGIN = "<!-- results: generated from benchmarks/results.json by benchmarks/results.py; tests/test_readme.py checks them -->"
END = "<!-- end results -->"
# The results the README quotes, against the peers a reader knows; docs/benchmarks.md gives them all.
README_KEYS = ("toolpath", "toolpath-quick", "dropcutter", "verify", "exact", "scatter", "simulate", "first-run")


def add_option(ap: argparse.ArgumentParser) -> None:
    """The ``--results`` option every benchmark takes: where its headline goes."""
    ap.add_argument("--results", type=Path, default=RESULTS,
                    help="results file to record the headline in (default benchmarks/results.json)")


def machine() -> str:
    """The processor's name and the number of cores this process may use."""
    name = platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                name = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return f"{name}, {cores} cores"


def significant(value: float, digits: int = 3) -> float:
    return float(f"{value:.{digits}g}")


def record(key: str, *, task: str, peer: str, ratio: float, detail: str, argv: list[str] | None = None,
           path: Path = RESULTS) -> dict:
    """Write one headline: ``peer`` takes ``ratio`` times lagsym's time at ``task``."""
    entry = {
        "task": task,
        "peer": peer,
        "ratio": significant(ratio),
        "detail": detail,
        "command": " ".join(["python3", f"benchmarks/{Path(sys.argv[0]).name}", *(argv if argv is not None else sys.argv[1:])]),
        "machine": machine(),
        "date": datetime.date.today().isoformat(),
        "load": round(os.getloadavg()[0], 1),
    }
    data = load(path)
    data[key] = entry
    path.write_text(json.dumps(dict(sorted(data.items())), indent=2, ensure_ascii=False) + "\n")
    if path.resolve() == RESULTS:
        render()
    print(f"\nrecorded in {path}: {headline(entry)}")
    return entry


def load(path: Path = RESULTS) -> dict:
    return json.loads(path.read_text()) if path.exists() else {}


def headline(entry: dict) -> str:
    """The one sentence the README and the docs quote for a result."""
    return f"{entry['task']}: {entry['peer']} takes {entry['ratio']:g}x as long"


def readme_lines(data: dict) -> str:
    return "\n".join(f"- {headline(data[k])}" for k in README_KEYS if k in data)


def page(data: dict) -> str:
    rows = "\n".join(
        f"| {e['task']} | {e['peer']} | {e['ratio']:g}x | {e['detail']} | `{e['command']}` | {e['machine']}; "
        f"{e['date']}; load {e['load']:g} |" for e in data.values())
    return f"""# Benchmarks

Generated from `benchmarks/results.json` by `benchmarks/results.py`; do not
edit.  Each script in `benchmarks/` times lagsym and a named peer doing the
same work in the same run, alternating where it can so that a busy spell of
a shared machine falls on both, and records the ratio below: the peer's time
over lagsym's.  Run a script again to replace its line; its docstring says
what it measures and how.

| task | peer | peer time / lagsym's | detail | command | machine; date; load |
|---|---|---:|---|---|---|
{rows}
"""


def readme_with(data: dict, text: str) -> str:
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    return f"{head}{BEGIN}\n{readme_lines(data)}\n{END}{tail}"


def render(path: Path = RESULTS) -> None:
    data = load(path)
    PAGE.write_text(page(data))
    README.write_text(readme_with(data, README.read_text()))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="only check that the pages are current")
    a = ap.parse_args(argv)
    data = load()
    if a.check:
        stale = [p.name for p, want in ((PAGE, page(data)), (README, readme_with(data, README.read_text())))
                 if not p.exists() or p.read_text() != want]
        if stale:
            print(f"not current: {', '.join(stale)} (run python3 benchmarks/results.py)")
            return 1
        return 0
    render()
    return 0


if __name__ == "__main__":
    sys.exit(main())
