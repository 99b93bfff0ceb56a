"""``lagsym check``: degree, Lebesgue constants and overshoot, and ``--strict``."""

from __future__ import annotations

import json

from conftest import EXAMPLES

EX4 = EXAMPLES / "paper-example-4.json"
CURVE3 = EXAMPLES / "paper-curve-3rd.json"


def test_check_reports_and_strict(run_cli, tmp_path):
    status, out, _ = run_cli("check", EX4)
    assert status == 0 and "degree in x: 4" in out and "Lebesgue constant" in out and "overshoot" in out
    high = tmp_path / "high.json"
    high.write_text(json.dumps({"x": list(range(9)), "y": [0, 1], "z": [[int(i == 4), 0] for i in range(9)]}))
    status, out, _ = run_cli("check", high)
    assert status == 0 and "WARNING degree in x: 8" in out
    assert run_cli("check", high, "--strict")[0] == 1
    doc = json.loads(run_cli("check", high, "--format", "json")[1])
    assert {f["name"] for f in doc["findings"] if f["warning"]} >= {"degree_x", "lebesgue_x", "overshoot"}


def test_check_curve(run_cli):
    status, out, _ = run_cli("check", CURVE3)
    assert status == 0 and "degree: 3" in out
