"""The ``lagsym`` command: parse arguments, call the library, print, map errors to exit statuses.

Each sub-command lives in its own module in this package, named as the command,
and defines ``DESCRIPTION``, ``add_arguments(parser)`` and
``run(args, out, err) -> int``; :data:`COMMANDS` lists them with their help
lines.  :func:`main` takes ``argv`` and the two streams so tests call it
directly.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import os
import signal
import sys
import threading
import traceback
from typing import IO, Sequence

from ..allocator import keep_freed_memory
from ..errors import ExitStatus, LagsymError, OutputError, Terminated
from ._lines import one_line

__all__ = ["main", "build_parser", "COMMANDS", "command_module"]

INTERNAL_ERROR = 70
ENGINE_POLICIES = ("auto", "numpy", "compiled")  # lagsym.evaluate.POLICIES, named here so --version loads no NumPy


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
        self.err.write(f"lagsym: error: {one_line(message)} (see '{self.prog} --help')\n")
        raise _ParserExit(ExitStatus.BAD_INPUT)


class _ParserExit(Exception):
    def __init__(self, status: int):
        self.status = status


# The commands in the order ``lagsym --help`` lists them (the order of the data flow), each with
# its one-line help.  A command's module (lagsym/cli/<name>.py) is imported only when that command
# runs or shows its own help, so ``lagsym --help`` and ``--version`` load no numeric library.
COMMANDS = {
    "equation": "print the exact Lagrange surface z = F(x, y) through a grid of control points",
    "curve": "print the exact Lagrange curve y = F(x) through a set of points",
    "probe": "write a probing program: measure the part on the machine at Chebyshev-spaced nodes",
    "read-probe": "read a probing program's results (DPRNT text, LinuxCNC log) into surface points",
    "fit": "fit an exact least-squares polynomial surface to measured points (a grid or scattered) and write it",
    "piecewise": "build exact C1 bicubic pieces through a grid too large for one polynomial and write them",
    "check": "measure degree, spacing ratio, Lebesgue constants, amplification of data errors and overshoot",
    "sample": "sample the surface densely and write the points (CSV, NumPy) or a mesh (VTK, STL, PLY, OBJ)",
    "export": "write the exact surface as a CAD file: STEP or IGES B-spline surface or solid, exact JSON",
    "compare": "compare the Lagrange surface with Hermite, Bezier and B-spline surfaces (the paper's Table 1)",
    "plot": "draw the surface, its basis functions or a curve (an image with -o, else a window)",
    "toolpath": "plan a raster toolpath over the exact surface and write it as G-code",
    "rough": "rough a block down to the surface in z levels and write it as G-code",
    "job": "write one program for a whole job file: roughing, finishing, tool changes, cycle time",
    "verify": "simulate a G-code program's cut on a height map: gouge, rapids into the part, material left",
    "macro": "write a macro program that evaluates the surface on the control (Fanuc, LinuxCNC, Heidenhain)",
    "simulate": "dry-run a macro program at the control's precision and write the moves it makes",
    "send": "send a program to a CNC control over RS-232 (upload to memory or drip feed)",
    "receive": "receive a program punched out by a CNC control over RS-232",
    "dnc": "run a DNC server: ports that machines call to punch programs and to ask for them",
}


def command_module(name: str):
    """The module of the command ``name`` (imported on first use)."""
    return importlib.import_module(f"{__name__}.{name.replace('-', '_')}")


def _chosen(argv: Sequence[str]) -> str | None:
    """The command named on the command line: its first word that is neither an option nor ``--engine``'s value."""
    words = iter(argv)
    for word in words:
        if word == "--engine":
            next(words, None)
        elif not word.startswith("-"):
            return word if word in COMMANDS else None
    return None


def build_parser(out: IO[str] = sys.stdout, err: IO[str] = sys.stderr, load=None) -> argparse.ArgumentParser:
    """The argument parser; the commands in ``load`` (default: all) get their full arguments."""
    from .. import __version__

    class Parser(_Parser):
        pass

    Parser.out, Parser.err = out, err
    # --traceback is accepted before or after the command: no default, so the command's parser cannot
    # undo a --traceback given before it (main reads it with getattr).
    common = Parser(add_help=False)
    common.add_argument("--traceback", action="store_true", default=argparse.SUPPRESS,
                        help="show the full traceback on an error")
    common.add_argument("--engine", choices=ENGINE_POLICIES, default=argparse.SUPPRESS,
                        help="how evaluation batches of 262,144 values or more run (sample, export, plot, verify): "
                             "auto (NumPy until such batches have taken 0.5 s, then the compiled kernels; the "
                             "default), numpy (never compiled), compiled (always); the values are the same "
                             "bit for bit")
    parser = Parser(
        prog="lagsym",
        description="Exact Lagrange surfaces from a few control points, to the machine.",
        parents=[common],
    )
    parser.add_argument("--version", action="version", version=f"lagsym {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    for name, help_line in COMMANDS.items():
        if load is not None and name not in load:
            sub.add_parser(name, help=help_line, parents=[common])
            continue
        mod = command_module(name)
        p = sub.add_parser(name, help=help_line, description=getattr(mod, "DESCRIPTION", help_line),
                           parents=[common], formatter_class=argparse.RawDescriptionHelpFormatter)
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run)
    return parser


def main(argv: Sequence[str] | None = None, stdout: IO[str] | None = None, stderr: IO[str] | None = None) -> int:
    """Run the ``lagsym`` command line and return its exit status."""
    out = stdout if stdout is not None else _StandardOutput(sys.stdout)
    err = stderr if stderr is not None else sys.stderr
    argv = list(sys.argv[1:] if argv is None else argv)
    try:  # Ctrl-C while the command's modules load: one line, as later
        if getattr(signal.getsignal(signal.SIGINT), "__module__", None) == "lagsym":  # the start-up's own
            signal.signal(signal.SIGINT, signal.default_int_handler)
        chosen = _chosen(argv)
        parser = build_parser(out, err, load=() if chosen is None else (chosen,))
        try:
            args = parser.parse_args(argv)
        except _ParserExit as e:
            return int(e.status)
    except Exception as e:  # a Ctrl-C some import wraps in its own error (a class's set-up in numpy)
        if not isinstance(e.__cause__ or e.__context__, KeyboardInterrupt):
            raise
        err.write("lagsym: interrupted; nothing was written\n")
        return ExitStatus.INTERRUPTED
    except KeyboardInterrupt:
        err.write("lagsym: interrupted; nothing was written\n")
        return ExitStatus.INTERRUPTED
    if not getattr(args, "_run", None):
        parser.print_help(out)
        return ExitStatus.BAD_INPUT
    keep_freed_memory()  # large temporaries reused rather than faulted in afresh (lagsym.allocator)
    try:
        from ._common import check_paths, in_program_units

        in_program_units(args)
        check_paths(args)
        with _signals_as_interrupts(), _notices(err), _engine(getattr(args, "engine", None)), _limits(args):
            status = int(args._run(args, out, err))
        out.flush()  # what is still buffered: a full disk says so here, not at the interpreter's exit
        return status
    except LagsymError as e:
        if getattr(args, "traceback", False):
            traceback.print_exc(file=err)
        err.write(f"lagsym: error: {one_line(str(e))}\n")
        return int(e.exit_status)
    except Terminated as e:
        err.write(f"lagsym: stopped by {signal.Signals(e.signum).name}; no partial output file is left\n")
        return 128 + e.signum
    except KeyboardInterrupt:
        err.write("lagsym: interrupted; no partial output file is left\n")
        return ExitStatus.INTERRUPTED
    except BrokenPipeError:
        return ExitStatus.OK
    except Exception as e:  # a bug in lagsym: say so in one line unless the user asks for more
        if getattr(args, "traceback", False):
            traceback.print_exc(file=err)
        else:
            err.write(f"lagsym: internal error: {type(e).__name__}: {one_line(str(e))} "
                      f"(run again with --traceback and report it)\n")
        return INTERNAL_ERROR


class _StandardOutput:
    """The process's standard output for a command: a write it cannot make (a full disk, a descriptor closed before
    the command started) is an :class:`~lagsym.errors.OutputError` that says so, as a file's would be."""

    def __init__(self, stream):
        self._stream = stream

    def _fail(self, e: OSError | None) -> OutputError:
        if e is None:
            return OutputError("standard output is closed: nothing could be written; give -o FILE or open it")
        from ..io.write import error_reason

        return OutputError(f"standard output: cannot write ({error_reason(e)}); give -o FILE to write a file instead")

    def write(self, text: str) -> int:
        if self._stream is None:
            raise self._fail(None)
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            raise
        except OSError as e:
            raise self._fail(e) from None

    def flush(self) -> None:
        if self._stream is None:
            return
        try:
            self._stream.flush()
        except BrokenPipeError:
            raise
        except OSError as e:
            raise self._fail(e) from None

    def __getattr__(self, name):  # isatty, fileno, encoding, buffer: the stream's own
        if self._stream is None:
            raise self._fail(None)
        return getattr(self._stream, name)


@contextlib.contextmanager
def _limits(args):
    """The command's ``--max-exact-s`` and ``--max-file-points`` around its work (a command without one: the default)."""
    with contextlib.ExitStack() as stack:
        if getattr(args, "max_exact_s", None) is not None:
            from ..exactsize import exact_time_limit

            stack.enter_context(exact_time_limit(args.max_exact_s))
        if getattr(args, "max_file_points", None) is not None:
            from ..io import file_points_limit

            stack.enter_context(file_points_limit(args.max_file_points))
        yield


@contextlib.contextmanager
def _engine(policy: str | None):
    """The evaluations of the command under an :class:`~lagsym.evaluate.Engine` of ``policy`` (None: the process's)."""
    if policy is None:
        yield
        return
    from ..evaluate import Engine, use_engine

    with use_engine(Engine(policy)):
        yield


@contextlib.contextmanager
def _notices(err: IO[str]):
    """An :class:`~lagsym.io.OutputNotice` from the library as one line on ``err``; other warnings as before."""
    import warnings

    from ..io import OutputNotice

    with warnings.catch_warnings():
        warnings.simplefilter("always", OutputNotice)
        shown = warnings.showwarning

        def show(message, category, filename, lineno, file=None, line=None):
            if issubclass(category, OutputNotice):
                err.write(f"lagsym: note: {one_line(str(message))}\n")
            else:
                shown(message, category, filename, lineno, file, line)

        warnings.showwarning = show
        yield


@contextlib.contextmanager
def _signals_as_interrupts():
    """SIGTERM and SIGHUP (a closed terminal) stop a command the way Ctrl-C does: temporary files removed,
    a transfer's resume block named, one line, exit 128 + the signal (143, 129)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    main_pid = os.getpid()

    def stop(signum, frame):
        if os.getpid() != main_pid:  # a forked worker not yet past its own set-up: end as the signal's default does
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)
            return
        raise Terminated(signum)

    old = {sig: signal.signal(sig, stop) for sig in (signal.SIGTERM, signal.SIGHUP)}
    try:
        yield
    finally:
        for sig, handler in old.items():
            signal.signal(sig, handler)


def run_console() -> None:
    """Entry point of the installed ``lagsym`` script."""
    try:
        status = main()
    except KeyboardInterrupt:  # between main's own handlers (a second Ctrl-C)
        sys.stderr.write("lagsym: interrupted\n")
        status = ExitStatus.INTERRUPTED
    try:
        if status != ExitStatus.INTERRUPTED:
            # the first command after an install leaves the cutter kernel compiling in the background
            from ..toolpath.warmup import start_in_background

            start_in_background()
    except KeyboardInterrupt:  # Ctrl-C as the command ends: the command's work is done, the compile not started
        sys.stderr.write("lagsym: interrupted\n")
        status = ExitStatus.INTERRUPTED
    sys.exit(status)
