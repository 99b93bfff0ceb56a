"""glibc's malloc kept from handing large freed arrays back: counted in page faults by the kernel."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

import lagsym.cli
from lagsym.allocator import keep_freed_memory

ROOT = Path(__file__).resolve().parent.parent
GLIBC = bool(getattr(os, "confstr_names", {}).get("CS_GNU_LIBC_VERSION")) and bool(os.confstr("CS_GNU_LIBC_VERSION"))

# Arrays of 12 and 40 MB made and freed forty times, as drop-cutter's temporaries are; the minor page faults
# the kernel counts for the loop (after three rounds to settle).
LOOP = """
import resource, sys
import numpy as np
if sys.argv[1] == "keep":
    from lagsym.allocator import keep_freed_memory
    assert keep_freed_memory()
def faults():
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(3):
    a = [np.ones(1_500_000) for _ in range(4)]; b = np.ones(5_000_000); del a, b
f = faults()
for _ in range(40):
    a = [np.ones(1_500_000) for _ in range(4)]; b = np.ones(5_000_000); del a, b
print(faults() - f)
"""


def _faults(mode: str, **env) -> int:
    environ = {k: v for k, v in os.environ.items() if not k.startswith("MALLOC_") and k != "GLIBC_TUNABLES"}
    done = subprocess.run([sys.executable, "-c", LOOP, mode], cwd=ROOT, capture_output=True, text=True,
                          env=dict(environ, PYTHONPATH=str(ROOT), **env), timeout=120)
    assert done.returncode == 0, done.stderr
    return int(done.stdout.split()[-1])


@pytest.mark.slow
@pytest.mark.skipif(not GLIBC, reason="glibc's malloc only")
def test_freed_arrays_are_reused_without_fresh_page_faults():
    plain, kept = _faults("plain"), _faults("keep")
    # 40 rounds of 88 MB: about 860,000 pages faulted in afresh by default; a few hundred once kept.
    assert plain > 100_000
    assert kept < plain / 50


@pytest.mark.parametrize("name", ["MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_", "GLIBC_TUNABLES"])
def test_the_users_own_malloc_tuning_is_left_alone(monkeypatch, name):
    monkeypatch.setenv(name, "1048576")
    assert keep_freed_memory() is False


def test_the_command_asks_for_it_before_it_runs(monkeypatch, capsys):
    calls = []
    monkeypatch.setattr(lagsym.cli, "keep_freed_memory", lambda: calls.append(1) or True)
    assert lagsym.cli.main(["equation", "examples/paper-example-1.json"]) == 0
    assert calls == [1]
