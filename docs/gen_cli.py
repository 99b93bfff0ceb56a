"""Write docs/cli.md from the ``lagsym`` parser itself: ``python3 docs/gen_cli.py``.

tests/test_docs.py checks that the page is current and runs its examples.
"""

from __future__ import annotations

import io
import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
WIDTH = "100"
if str(HERE.parent) not in sys.path:
    sys.path.insert(0, str(HERE.parent))


def help_text(argv: list[str]) -> str:
    """What ``lagsym ARGV --help`` prints, at a fixed width."""
    from lagsym.cli import main

    old = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = WIDTH
    try:
        out = io.StringIO()
        main([*argv, "--help"], out, io.StringIO())
        return out.getvalue().rstrip() + "\n"
    finally:
        if old is None:
            del os.environ["COLUMNS"]
        else:
            os.environ["COLUMNS"] = old


def page() -> str:
    """The whole CLI reference page."""
    from lagsym.cli import COMMANDS

    parts = [
        "# CLI reference\n",
        "Every command of `lagsym`, as its `--help` prints it.  This page is generated from the",
        "parser (`python3 docs/gen_cli.py`), and the tests check that it is current and run the",
        "examples under each command, so neither can drift from the program.\n",
        "Exit statuses: 0 success; 1 a finding (`check --strict` warning, `verify` gouge, rapid crash or material left);",
        "2 bad input or options (one line on standard error naming the file and value, nothing",
        "written), or a standard output that cannot be written (full or closed); 3 a fault on",
        "the serial line or at the machine (the message says what to do next); 129, 130, 143",
        "stopped by SIGHUP, Ctrl-C, SIGTERM (no partial file left); 70 an",
        "internal error (a bug: one line, `--traceback` for the details).  `--traceback` on any",
        "command shows the Python traceback of an error.\n",
        "Every numeric option is checked as it is read: a finite number within the range its",
        "error message states (NaN, infinities, non-ASCII digits are refused).  Work that could",
        "run away is estimated before it starts and refused beyond a limit that an option lifts:",
        "`sample --max-points` (default 1e8 points), `toolpath --max-points` (5e6 fine",
        "drop-cutter samples, some 1.5 GB at the peak), `rough` and `job --max-points` (5e6 points an",
        "operation) and",
        "`--max-samples` (1e5 drop-cutter samples a roughing level), `verify --max-cells` (1.6e7",
        "height-map cells), `--max-contacts` (2e10 segments swept times cells under the tool) and",
        "`--max-moves` (2e6 points of the program's moves, each arc read as pieces, counted as it is read),",
        "`equation --max-terms` (2500 terms), and `--max-exact-mb` (400 MB) on every command that",
        "computes an exact polynomial from points (`curve`, `equation`, `check`, `sample`, `export`,",
        "`plot`, `toolpath`, `rough`, `job`, `macro`, `verify`, `compare`, `simulate --surface`): the size of",
        "its rationals, estimated from the",
        "number of nodes, their denominators and span before any of it is made (a curve of 1000",
        "points 0.1 apart: 2.7 GB; of 500 points: 306 MB).  Within the limit, Ctrl-C and SIGTERM still",
        "act within about a second while the exact polynomial is made: its matrix products run a few rows at",
        "a time (a whole product for a 60x60 grid of decimal nodes is one call of several seconds).",
        "The size says little of the time (decimal nodes cost far more than small integers), so",
        "`--max-exact-s` (15 s), on the same commands, limits a command's exact computations together,",
        "the polynomial and the change of basis its evaluation uses: once a product has",
        "run half a second, the pace of its rows foretells when it ends, and one foreseen to end more",
        "than that after the command began is refused with that figure (a 100x100 grid of",
        "nodes with three decimals: about a minute, refused a few seconds in).",
        "A program `simulate` runs that would never end",
        "stops within seconds with the runaway alarm (exit 2): at once when a loop can be seen in",
        "the text never to end (its condition one nothing in it changes) or the run comes back to a",
        "block with nothing changed, else after",
        "`--max-idle-blocks` (200000 blocks without a move) or `--max-blocks` (5e6 blocks, 37",
        "bytes a move at most); a program of more than `--max-lines` (100000) lines, or of more bracketed",
        "expressions (each `[`, about 0.1 ms to read and compile) than that, is refused before it is read",
        "into blocks (each line takes about 11 KB while read and compiled).",
        "`receive --timeout` and `--idle-timeout` are at most 86400 s;",
        "`send` and `receive` check a `--port` URL (scheme, host, port 1-65535, options) and",
        "that the `--log` file takes a line before the port opens (exit 2), and report a log",
        "lost part way (a disk that fills) with exit 3 rather than the transfer as done.",
        "Input files are limited as docs/formats.md says.\n",
        "`-o FILE`, and every other output (`--print-output`, `--plot`, `--log`), is checked before",
        "any work: a folder, a missing folder, a symbolic-link loop, a name or a whole path (a",
        "relative one made absolute too) longer than the system allows, a file that is also one of",
        "the command's inputs (the same file by any name: device and inode; for `job`, the job",
        "file's points file too) or the file another output of the command names is refused with",
        "exit 2.  A regular file, or a new name, is written to a hidden temporary file beside it",
        "(its name within the file system's limit) and renamed over it only when complete, so a stop",
        "or a full disk leaves the earlier file as it was; a file with other hard links becomes a",
        "new file, and a note on standard error says the other links keep the old content.  A",
        "device, pipe or socket (`/dev/null`, `/dev/stdout`, a FIFO), told by what it is, not by its",
        "name, is written through once the content is complete.  Every message that names a file",
        "(an error, a warning, a note such as how a table was read, a summary) is one line: a",
        "control character in a file name is shown escaped (`\\n`).\n",
        "```",
        help_text([]).rstrip(),
        "```\n",
    ]
    for name in COMMANDS:
        parts += [f"## lagsym {name}\n", "```", help_text([name]).rstrip(), "```\n"]
    return "\n".join(parts)


if __name__ == "__main__":
    (HERE / "cli.md").write_text(page())
    print(f"wrote {HERE / 'cli.md'}")
