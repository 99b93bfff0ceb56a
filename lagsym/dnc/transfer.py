"""What a send puts on the line and the send itself: :func:`transfer_segments` and :func:`send_program`.

The pacing, XON/XOFF and accounting are :mod:`lagsym.dnc.sender`'s; the
receiver is :mod:`lagsym.dnc.receiver`.  Nothing here imports serial:
:func:`send_program` opens the line through :mod:`lagsym.dnc.port` when it is
called, so the settings, the framing and :func:`transfer_segments` work where
pyserial is not loaded.
"""

from __future__ import annotations

from collections.abc import Callable

from ..errors import InputError, TransferError, stopped_by
from ..values import choice
from .blocks import Program, check_drip, check_iso, frame, tv_padded
from .priority import realtime
from .results import LineFault, TransferProgress, TransferResult
from .resume import first_resumable_block, resume_setup
from .settings import MODES, LineSettings

__all__ = ["TransferProgress", "TransferResult", "LineFault", "transfer_segments", "send_program"]


def transfer_segments(program: Program, settings: LineSettings, mode: str = "upload", start_block: int = 1,
                      safe_z: str | None = None) -> list[tuple[int | None, bytes]]:
    """The exact bytes a send puts on the line, as ``(block number or None, bytes)`` segments.

    With ``start_block`` above 1 (drip only) the modal set-up from
    :func:`lagsym.dnc.resume_setup` goes first, then block ``start_block``
    onwards.

    Examples
    --------
    >>> from lagsym.dnc import parse_program
    >>> p = parse_program("O1\\nM30")
    >>> b"".join(b for _, b in transfer_segments(p, LineSettings(line_ending="crlf")))
    b'%\\r\\nO1\\r\\nM30\\r\\n%\\r\\n'
    """
    choice(mode, MODES, "mode")
    if isinstance(start_block, bool) or not isinstance(start_block, int) or start_block < 1:
        raise InputError(f"--start-block {start_block!r} must be a block number from 1")
    blocks: list[tuple[int | None, str]] = []
    if start_block > 1:
        if mode != "drip":
            raise InputError("--start-block resumes a drip feed; an upload stores the whole program, so send it whole")
        blocks.extend((None, b) for b in resume_setup(program, start_block, safe_z))
    elif safe_z is not None:
        raise InputError("--safe-z only applies with --start-block above 1")
    blocks.extend((n, program.block(n)) for n in range(start_block, len(program) + 1))
    if mode == "drip":
        check_drip(program)
    if settings.iso_check:
        check_iso(program)
    if settings.tv_check:
        blocks = [(n, tv_padded(text, settings.eol)) for n, text in blocks]
    segments = frame(blocks, settings.eol, settings.percent, settings.leader, settings.trailer)
    size = sum(len(chunk) for _, chunk in segments)
    if mode == "upload" and settings.memory_chars is not None and size > settings.memory_chars:
        raise InputError(f"{program.source}: {size} characters do not fit the control's memory of "
                         f"{settings.memory_chars}; drip-feed it (--mode drip) or free memory and raise "
                         "--memory-chars")
    return segments


def send_program(port: str, program: Program, settings: LineSettings, mode: str = "upload", *,
                 start_block: int = 1, safe_z: str | None = None,
                 progress: Callable[[TransferProgress], None] | None = None, log: Callable[[str], None] | None = None,
                 line=None, stray: Callable[[bytes], None] | None = None) -> TransferResult:
    """Send a program to a control over a serial line.

    Parameters
    ----------
    port : str
        A device (``/dev/ttyUSB0``, ``COM3``) or a pyserial URL
        (``socket://host:port``, ``rfc2217://host:port``, ``loop://``).
    program : Program
        From :func:`lagsym.dnc.parse_program`.
    settings : LineSettings
        The line set-up, e.g. ``profile("fanuc")``.
    mode : str
        ``upload`` stores the program in the control's memory; ``drip``
        feeds it while the control runs it.
    start_block : int
        Resume a drip feed at this block (see :mod:`lagsym.dnc.blocks` for the
        numbering); the modal set-up is sent first.
    safe_z : str, optional
        Retract height for a resume, in program units.
    progress : callable, optional
        Called about ten times a second with a :class:`TransferProgress`.
    log : callable, optional
        Called with one line of text per event (XOFF, XON, fault, end).
    line : lagsym.dnc.port.Port, optional
        A port already open (a service keeps its port), used and left open.
    stray : callable, optional
        Given the characters from the control that stopped the send as no
        flow control (from the first such one on), before the fault: a
        service keeps them, since they may be the start of a punch.

    Returns
    -------
    TransferResult

    Raises
    ------
    LineFault
        On a stall, a lost line, Ctrl-C, SIGTERM or SIGHUP, naming the last block that surely
        arrived and the ``--start-block`` to resume with.
    TransferError
        If the port cannot be opened, or real-time priority
        (``settings.realtime``) is refused.
    InputError
        For a bad mode, start block or resume.
    """
    segments = transfer_segments(program, settings, mode, start_block, safe_z)
    with realtime(settings.realtime):  # refused before the port opens
        return _send(port, program, settings, mode, start_block=start_block, segments=segments, progress=progress,
                     log=log, line=line, stray=stray)


def _send(port, program, settings, mode, *, start_block, segments, progress, log, line, stray) -> TransferResult:
    """Open the line (unless given one), run the sender and name every fault truly."""
    from .port import LINE_ERRORS, Port, WriteTimeout  # serial loads only when a line is used
    from .sender import Sender

    timeout = None if settings.stall_timeout_s == float("inf") else settings.stall_timeout_s
    owned = line is None
    if owned:
        try:
            line = Port(port, settings, write_timeout=timeout)
        except KeyboardInterrupt as e:
            raise TransferError(f"{stopped_by(e)} while opening {port}; nothing was sent: "
                                "send the program again") from None
    try:
        sender = Sender(line, segments, settings, mode, port, progress=progress, log=log,
                        resumable_from=first_resumable_block(program) if start_block <= 1 else 2, stray=stray)
    except BaseException:
        if owned:
            line.close()
        raise
    try:
        return sender.run()
    except KeyboardInterrupt as e:  # Ctrl-C, and SIGTERM or SIGHUP as the CLI raises them (Terminated)
        raise sender.interrupted(e) from None
    except TransferError:
        raise  # the sender's own stall fault: an OSError too, but not a lost line
    except WriteTimeout:
        raise sender.fault(f"a write waited more than {settings.stall_text}",
                           "check the cable, the flow control setting and that the control is reading") from None
    except LINE_ERRORS as e:
        reason = str(e).strip() or type(e).__name__
        raise sender.fault(f"the line was lost ({reason})",
                           "reconnect the cable or the network port and clear the control") from None
    finally:
        if owned:
            line.close()


