"""The ``lagsym`` command: parse arguments, call the library, print, map errors to exit statuses.

Each sub-command lives in its own module in this package and defines ``NAME``,
``ORDER``, ``HELP``, ``add_arguments(parser)`` and ``run(args, out, err) -> int``.
:func:`main` takes ``argv`` and the two streams so tests call it directly.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
import traceback
from typing import IO, Sequence

from ..errors import ExitStatus, LagsymError

__all__ = ["main", "build_parser"]

INTERNAL_ERROR = 70


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser that writes to the streams :func:`main` was given and never exits by itself."""

    out: IO[str] = sys.stdout
    err: IO[str] = sys.stderr

    def _print_message(self, message, file=None):  # noqa: D401 - argparse hook
        if message:
            (self.err if file is sys.stderr else self.out).write(message)

    def exit(self, status=0, message=None):
        if message:
            self.err.write(message)
        raise _ParserExit(status)

    def error(self, message):
        self.err.write(f"lagsym: error: {message} (see '{self.prog} --help')\n")
        raise _ParserExit(ExitStatus.BAD_INPUT)


class _ParserExit(Exception):
    def __init__(self, status: int):
        self.status = status


def _commands():
    from . import __name__ as pkg, __path__ as path

    mods = []
    for info in pkgutil.iter_modules(path):
        if info.name.startswith("_"):
            continue
        mod = importlib.import_module(f"{pkg}.{info.name}")
        if hasattr(mod, "NAME") and hasattr(mod, "run"):
            mods.append(mod)
    return sorted(mods, key=lambda m: (getattr(m, "ORDER", 100), m.NAME))


def build_parser(out: IO[str] = sys.stdout, err: IO[str] = sys.stderr) -> argparse.ArgumentParser:
    """The argument parser with every sub-command registered."""
    from .. import __version__

    class Parser(_Parser):
        pass

    Parser.out, Parser.err = out, err
    common = Parser(add_help=False)
    common.add_argument("--traceback", action="store_true", help="show the full traceback on an error")
    parser = Parser(
        prog="lagsym",
        description="Exact Lagrange surfaces from a few control points, to the machine.",
        parents=[common],
    )
    parser.add_argument("--version", action="version", version=f"lagsym {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    for mod in _commands():
        p = sub.add_parser(mod.NAME, help=mod.HELP, description=getattr(mod, "DESCRIPTION", mod.HELP), parents=[common],
                           formatter_class=argparse.RawDescriptionHelpFormatter)
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run)
    return parser


def main(argv: Sequence[str] | None = None, stdout: IO[str] | None = None, stderr: IO[str] | None = None) -> int:
    """Run the ``lagsym`` command line and return its exit status."""
    out = stdout if stdout is not None else sys.stdout
    err = stderr if stderr is not None else sys.stderr
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser(out, err)
    try:
        args = parser.parse_args(argv)
    except _ParserExit as e:
        return int(e.status)
    if not getattr(args, "_run", None):
        parser.print_help(out)
        return ExitStatus.BAD_INPUT
    try:
        return int(args._run(args, out, err))
    except LagsymError as e:
        if args.traceback:
            traceback.print_exc(file=err)
        err.write(f"lagsym: error: {e}\n")
        return int(e.exit_status)
    except KeyboardInterrupt:
        err.write("lagsym: interrupted\n")
        return ExitStatus.INTERRUPTED
    except BrokenPipeError:
        return ExitStatus.OK
    except Exception as e:  # a bug in lagsym: say so in one line unless the user asks for more
        if args.traceback:
            traceback.print_exc(file=err)
        else:
            err.write(f"lagsym: internal error: {type(e).__name__}: {e} (run again with --traceback and report it)\n")
        return INTERNAL_ERROR


def run_console() -> None:
    """Entry point of the installed ``lagsym`` script."""
    sys.exit(main())
