"""The layout is itself tested: imports flow one way (import-linter), start-up is cheap, modules stay small."""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys

import pytest

from conftest import ROOT

LINT = ("import sys; from importlinter.cli import lint_imports; "
        "sys.exit(lint_imports(config_filename='pyproject.toml', no_cache=True))")
MAX_MODULE_LINES = 450
MAX_FUNCTION_LINES = 80
LONG_FUNCTION_NOTE = "Long because"  # the docstring of a longer function says why it is one piece


def _lint(where) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", LINT], cwd=where, capture_output=True, text=True, timeout=300)


def test_the_import_contracts_hold():
    done = _lint(ROOT)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    assert "0 broken" in done.stdout


@pytest.mark.parametrize("module, line, broken", [
    ("lagrange.py", "from . import sampling  # noqa: F401", "lagsym.lagrange -> lagsym.sampling"),
    ("grid.py", "from .toolpath import drop_cutter  # noqa: F401", "lagsym.grid -> lagsym.toolpath"),
    ("evaluate.py", "import serial  # noqa: F401", "lagsym.evaluate -> serial"),
    ("toolpath/plan.py", "import rich  # noqa: F401", "lagsym.toolpath.plan -> rich"),
])
def test_a_reintroduced_cycle_or_stray_import_fails(tmp_path, module, line, broken):
    """The contract is not vacuous: put one wrong import back and it breaks, naming the import."""
    shutil.copytree(ROOT / "lagsym", tmp_path / "lagsym", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    target = tmp_path / "lagsym" / module
    if not target.exists():
        target = target.with_suffix("") / "__init__.py"
    target.write_text(target.read_text() + "\n" + line + "\n")
    done = _lint(tmp_path)
    assert done.returncode != 0
    assert broken in done.stdout, done.stdout[-4000:]


def test_import_lagsym_loads_no_heavy_library():
    code = ("import sys, lagsym; from lagsym.cli import main; main(['--help'], open('/dev/null', 'w')); "
            "print(' '.join(sorted(m for m in ('serial', 'pyvista', 'vtkmodules', 'meshio', 'rich', 'sympy', "
            "'numpy', 'flint', 'scipy', 'numba') if m in sys.modules)))")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == ""


@pytest.mark.slow
def test_the_plain_library_does_not_load_serial_pictures_or_numba():
    code = ("import sys; from lagsym import lagrange_surface, read_points, sample, plan_toolpath, macro_program, "
            "simulate, parse_program, LineSettings; "
            "print(' '.join(sorted(m for m in ('serial', 'pyvista', 'vtkmodules', 'meshio', 'rich', 'numba') "
            "if m in sys.modules)))")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == ""


def _modules():
    return sorted(p for p in (ROOT / "lagsym").rglob("*.py") if "__pycache__" not in p.parts)


def test_no_module_is_too_long():
    long = {str(p.relative_to(ROOT)): n for p in _modules() if (n := len(p.read_text().splitlines())) > MAX_MODULE_LINES}
    assert long == {}


@pytest.mark.slow
def test_no_function_is_too_long_without_a_reason():
    long = []
    for p in _modules():
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > MAX_FUNCTION_LINES and LONG_FUNCTION_NOTE not in (ast.get_docstring(node) or ""):
                    long.append(f"{p.relative_to(ROOT)}:{node.lineno} {node.name} ({n} lines)")
    assert long == []
