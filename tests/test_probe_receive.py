"""Probe results over the serial line: a simulated Fanuc's DPRNT output punched over a pty pair to ``lagsym receive``
and to the DNC server."""

from __future__ import annotations

import io
import re
import subprocess
import sys
from pathlib import Path

import pytest

from lagsym.cli import main
from lagsym.formula import parse_formula
from lagsym.probe import ProbeSettings, node_plan, probe_program
from lagsym.simulate import simulate
from lagsym.simulate.probing import probe_target

from simcontrol import PtyPair, punch, wait_until
from test_probe import TOLERANCE, _centre_heights, _moves

pytestmark = pytest.mark.socat
ROOT = Path(__file__).resolve().parent.parent
TRUE = "3 + 0.02*x + 0.0006*y**2 - 0.00003*x**2 + 0.00001*x*y"
DC2, DC4 = b"\x12", b"\x14"


def _printed() -> list[str]:
    """What the simulated control prints between POPEN and PCLOS."""
    text = probe_program(node_plan((0, 40, 0, 30), 2, margin=1), ProbeSettings(1, 6, 2), "fanuc")
    return list(simulate(text, "fanuc", 8, target=probe_target(parse_formula(TRUE), 1)).output)


def _receive(pair, target, *extra):
    return subprocess.Popen([sys.executable, "-m", "lagsym", "receive", "--port", pair.near, "--baud", "38400",
                             "--timeout", "60", "-o", str(target), *extra], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)


@pytest.mark.slow
def test_dprnt_output_received_as_probe_results_then_fitted(tmp_path):
    lines = _printed()
    target = tmp_path / "results.txt"
    with PtyPair() as pair:
        proc = _receive(pair, target)
        assert b"start the output (PUNCH)" in proc.stderr.readline()
        # POPEN sends DC2, each DPRNT a line ended by CR LF, PCLOS DC4
        punch(pair.far, DC2 + "".join(line + "\r\n" for line in lines).encode("ascii") + DC4, 38400)
        out, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err
    assert target.read_text() == "".join(line.rstrip() + "\n" for line in lines)
    assert f"probe results: {len(lines) - 2} nodes, tip radius 1 mm".encode() in err
    o, e = io.StringIO(), io.StringIO()
    assert main(["fit", str(target), "--degree", "2", "-o", str(tmp_path / "s.json")], o, e) == 0, e.getvalue()
    largest = float(re.search(r"residuals: max ([\d.e+-]+)", o.getvalue() + e.getvalue()).group(1))
    # ... and machined: the finishing program from the received results, checked by brute force against the formula
    nc = tmp_path / "part.nc"
    o, e = io.StringIO(), io.StringIO()
    assert main(["toolpath", str(tmp_path / "s.json"), "--tool-diameter", "6", "--stepover", "2", "--step", "1",
                 "--tolerance", str(TOLERANCE), "--safe-z", "20", "-o", str(nc)], o, e) == 0, e.getvalue()
    pts = _moves(nc.read_text())
    over = pts[(pts[:, 0] >= 0) & (pts[:, 0] <= 40) & (pts[:, 1] >= 0) & (pts[:, 1] <= 30)]
    assert len(over) > 100
    at = over[:, 2] + 3.0 - _centre_heights(parse_formula(TRUE), over[:, 0], over[:, 1], 3.0)
    stated = largest + 5e-5 + 1e-4 + 2e-5  # the fit, the printed digit, the tip compensation, the brute force
    assert -at.min() <= stated, (at.min(), stated)
    assert at.max() <= stated + TOLERANCE + 5e-4, (at.max(), stated)


@pytest.mark.slow
def test_a_dprnt_stream_cut_mid_line_is_refused_naming_the_node(tmp_path):
    lines = _printed()
    data = "".join(line + "\r\n" for line in lines).encode("ascii")
    cut = data.index(b"P 5 ") + 14  # inside node 5's line; then the line goes quiet
    target = tmp_path / "results.txt"
    with PtyPair() as pair:
        proc = _receive(pair, target, "--idle-timeout", "1")
        assert b"start the output (PUNCH)" in proc.stderr.readline()
        punch(pair.far, DC2 + data[:cut], 38400)
        out, err = proc.communicate(timeout=60)
    assert proc.returncode == 2, err
    assert err.count(b"\n") == 1 and err.startswith(b"lagsym: error:"), err
    assert b"node 5: the line is cut mid-way" in err, err
    assert not target.exists()


@pytest.mark.slow
def test_the_dnc_server_keeps_probe_results_and_refuses_a_missing_node(tmp_path):
    """A DPRNT punch to ``lagsym dnc serve``: kept as probe-results.txt; one with a node missing in failed/."""
    import os
    import re
    import time

    config_text = re.search(r"```toml\n(.*?)```", (ROOT / "docs" / "dnc.md").read_text(), re.DOTALL).group(1)
    lines = _printed()
    data = "".join(line + "\r\n" for line in lines).encode("ascii")
    missing = data.replace(("".join(line + "\r\n" for line in lines[3:4])).encode("ascii"), b"")
    mill, lathe = PtyPair(), PtyPair()
    (tmp_path / "dnc" / "programs").mkdir(parents=True)
    cfg = tmp_path / "dnc.toml"
    cfg.write_text(config_text.replace("/dev/ttyUSB0", mill.near).replace("/dev/ttyUSB1", lathe.near))
    proc = subprocess.Popen([sys.executable, "-m", "lagsym", "dnc", "serve", str(cfg)], cwd=tmp_path,
                            env=dict(os.environ, PYTHONPATH=str(ROOT)), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    received = tmp_path / "dnc" / "received" / "mill1"
    log = tmp_path / "dnc" / "mill1.log"

    try:
        assert wait_until(lambda: log.exists() and "listening" in proc.stdout.readline())
        time.sleep(0.5)
        punch(mill.far, DC2 + data + DC4, 19200)
        assert wait_until(lambda: (received / "probe-results.txt").exists())
        assert (received / "probe-results.txt").read_text() == "".join(line.rstrip() + "\n" for line in lines)
        assert wait_until(lambda: f"received probe results: {len(lines) - 2} nodes" in log.read_text())
        punch(mill.far, DC2 + missing + DC4, 19200)
        assert wait_until(lambda: "failed probe results" in log.read_text())
        assert "node 3 of 16 missing" in log.read_text()
        assert not (received / "probe-results.received-2.txt").exists()
        reasons = list((received / "failed").glob("*.reason"))
        assert len(reasons) == 1 and "node 3 of 16 missing" in reasons[0].read_text()
    finally:
        proc.terminate()
        proc.communicate(timeout=10)
        mill.close()
        lathe.close()
