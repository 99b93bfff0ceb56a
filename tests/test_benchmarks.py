"""The start-up benchmarks run as the README says and print their tables (one run each: times are not checked)."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.slow
@pytest.mark.parametrize("script, base, rows", [("bench_startup.py", "lagsym --version", 5),
                                                ("bench_equation.py", "lagsym equation", 3)])
def test_a_start_up_benchmark_prints_its_ratios(script, base, rows, tmp_path):
    results = tmp_path / "results.json"
    done = subprocess.run([sys.executable, str(ROOT / "benchmarks" / script), "--runs", "1", "--results", str(results)],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    lines = [ln for ln in done.stdout.splitlines() if ln.startswith("| ") and not ln.startswith("| command")]
    assert len(lines) == rows
    assert lines[0].startswith(f"| {base} |") and lines[0].endswith("| 1.00x / 1.00x |")
    for ln in lines:
        lo, med = (float(v) for v in re.findall(r"\| (\d+\.\d{3}) ", ln)[:2])
        assert 0 < lo <= med < 60
    # Its headline went into the results file it was given (and nowhere else): this command, a ratio.
    import json

    (entry,) = json.loads(results.read_text()).values()
    assert entry["command"].endswith(f"benchmarks/{script} --runs 1 --results {results}")
    assert entry["ratio"] > 0 and entry["date"] and entry["machine"]

