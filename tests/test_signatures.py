"""Parameter lists stay short: past six positional parameters, the rest travel as a value or keyword-only arguments.

Six positions are as many as a reader keeps apart at a call; after that a
call reads ``f(a, b, c, d, e, f, tol=..., radius=...)``, or the parameters
that always travel together become one small frozen value.
"""

from __future__ import annotations

import ast

from conftest import ROOT

MAX_POSITIONAL = 6

# Compiled by Numba in nopython mode, where keyword-only arguments and dataclasses are not free: these take
# their arrays and numbers by position, and Python reaches each only through one thin wrapper
# (kernel.drop_chunk through dropcutter._drop_chunk, kernel.newton_starts through newton.newton_ball,
# compiled.points_kernel through the evaluator, piecekernel.part_bounds through dropcutter._piece_bounds); the
# others are called only by other kernels.
KERNELS = {
    "toolpath/kernel.py:_values",
    "toolpath/kernel.py:_jet",
    "toolpath/kernel.py:_candidates",
    "toolpath/kernel.py:_heights",
    "toolpath/kernel.py:_starts",
    "toolpath/kernel.py:_distinct",
    "toolpath/kernel.py:_ranked",
    "toolpath/kernel.py:_contact",
    "toolpath/kernel.py:_newton",
    "toolpath/kernel.py:_refine",
    "toolpath/kernel.py:drop_chunk",
    "toolpath/kernel.py:newton_starts",
    "toolpath/piecekernel.py:part_bounds",
    "evaluate/compiled.py:_basis",
    "evaluate/compiled.py:points_kernel",
    "evaluate/compiled.py:_first_terms",
    "evaluate/compiled.py:_four_more_terms",
}

# A kernel's one wrapper called with a task tuple by the worker pool (workers.map), so by position.
WRAPPERS = {
    "toolpath/dropcutter.py:_drop_chunk",
}


def _long_signatures() -> dict[str, int]:
    """``{"path:qualname": positional count}`` of every function in lagsym over :data:`MAX_POSITIONAL`."""
    found = {}
    package = ROOT / "lagsym"
    for path in sorted(package.rglob("*.py")):
        name = path.relative_to(package).as_posix()

        def visit(node, prefix):
            for child in ast.iter_child_nodes(node):
                if isinstance(child, ast.ClassDef):
                    visit(child, prefix + child.name + ".")
                elif isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    params = [a.arg for a in child.args.posonlyargs + child.args.args]
                    if params and params[0] in ("self", "cls"):
                        params = params[1:]
                    if len(params) > MAX_POSITIONAL:
                        found[f"{name}:{prefix}{child.name}"] = len(params)
                    visit(child, prefix + child.name + ".<locals>.")
                else:
                    visit(child, prefix)

        visit(ast.parse(path.read_text(encoding="utf-8"), str(path)), "")
    return found


def test_no_function_takes_more_than_six_positional_parameters():
    long = {k: n for k, n in _long_signatures().items() if k not in KERNELS | WRAPPERS}
    assert not long, "more than six positional parameters (make the tail keyword-only with `*,` or group " \
        "what travels together in a frozen value): " + ", ".join(f"{k} ({n})" for k, n in sorted(long.items()))


def test_the_allow_lists_name_only_long_signatures():
    """An entry whose function was split, renamed or removed leaves the lists."""
    stale = (KERNELS | WRAPPERS) - set(_long_signatures())
    assert not stale, "allowed but no longer long (remove from the list): " + ", ".join(sorted(stale))
