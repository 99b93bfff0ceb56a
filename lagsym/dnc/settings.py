"""How the serial line to a control is set up: :class:`LineSettings` and the usual profile of each control family.

Plain values, checked when they are made; nothing here opens a port, so
parities are the letters pyserial takes (``N``, ``E``, ``O``, ``M``, ``S``)
rather than its constants.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..errors import InputError
from ..machine import LINE_ENDINGS, bits_per_char
from ..values import choice, positive
from .blocks import DC1, DC2, DC3, DC4

__all__ = ["LineSettings", "PROFILES", "FLOW_CONTROLS", "CARRIERS", "PARITIES", "MODES", "URL_SCHEMES", "profile",
           "parse_filler", "check_port"]

FLOW_CONTROLS = ("xonxoff", "rtscts", "dtrdsr", "none")
CARRIERS = ("none", "dsr", "cd", "cts")
PARITIES = {"none": "N", "even": "E", "odd": "O", "mark": "M", "space": "S"}
MODES = ("upload", "drip")
# pyserial's URL handlers; the options of the three lagsym documents are checked here, because pyserial
# answers a bad one with an error of its own formatting (a KeyError) rather than a message.
URL_SCHEMES = ("socket", "rfc2217", "loop", "spy", "hwgrep", "alt", "cp2110")
_URL_OPTIONS = {"loop": ("logging",), "socket": ("logging",),
                "rfc2217": ("logging", "ign_set_control", "poll_modem", "timeout")}
_LOGGING = ("debug", "info", "warning", "error")
_FILLERS = {"NUL": "\x00", "SPACE": " ", "ETX": "\x03", "EOT": "\x04", "CR": "\r", "LF": "\n", "DEL": "\x7f"}


# The settings that are numbers, as messages name them.
_NUMBERS = {"baud": "baud rate", "bytesize": "data bits", "stopbits": "stop bits",
            "stall_timeout_s": "stall timeout (seconds)", "overrun_chars": "overrun limit",
            "buffer_chars": "control buffer", "memory_chars": "control memory"}


@dataclass(frozen=True)
class LineSettings:
    """How the serial line to one control is set up.

    Attributes
    ----------
    baud : int
        Bits per second.
    bytesize : int
        Data bits, 7 or 8 (5 and 6 are accepted for odd hardware).
    parity : str
        ``none``, ``even``, ``odd``, ``mark`` or ``space``.
    stopbits : float
        1, 1.5 or 2.
    flow : str
        ``xonxoff`` (DC1/DC3 from the control, handled by lagsym), ``rtscts``
        or ``dtrdsr`` (hardware: the sender pauses while CTS or DSR is low)
        or ``none``.
    carrier : str
        A signal the control holds up for as long as it is connected and
        reading: ``dsr``, ``cd`` (DCD) or ``cts``; ``none`` where the cable
        carries none.  It dropping for :data:`CARRIER_LOSS_S` is a lost line,
        and it is what confirms that the control took the program.
    line_ending : str
        End of block: ``lf``, ``crlf`` or ``cr`` (the characters are
        :attr:`eol`).
    leader, trailer : str
        Characters sent before and after the program (tape feed, ETX).
    percent : bool
        Frame the program with ``%`` lines.
    dtr : bool
        Assert DTR while the port is open.
    stall_timeout_s : float
        Longest XOFF, CTS low or stopped output queue before the transfer
        gives up; ``math.inf`` waits for ever (a long M00 or feed hold).  In a
        drip feed it must exceed the longest time the control spends on the
        blocks in its buffer.
    overrun_chars : int
        Most characters on their way at any moment: what arrives after the
        control says XOFF is these and at most one write that left before
        lagsym read the DC3.  Keep it to about half the control's tolerance
        (about 10 on a Fanuc); a larger window keeps a fast line busy when
        the computer wakes the sender late.
    wait_for_xon : bool
        Wait for the control's DC1 before the first character (a Fanuc sends
        it when READ is pressed).
    buffer_chars : int
        The control's input buffer in a drip feed: characters that may have
        arrived but not yet run.  A fault's resume block allows for them.
    memory_chars : int or None
        The control's program memory; a larger upload is refused.  None:
        not known.
    tv_check : bool
        Pad every block with a space so that it and its end of block have
        an even number of characters, for a control that checks it (TV check).
    iso_check : bool
        Refuse characters outside the ISO 840 tape code in what is sent, and
        report them in what is received.
    handshake_expected : bool
        A drip feed expects the control to answer with flow control (DC3 or
        DC1, or the CTS/DSR/carrier signals) at least once: a drip feed the
        control never answered ends as a fault, since nothing shows that a
        control took any of it.  False for a control that reads faster than
        the line and never says XOFF.
    realtime : bool
        Send from a thread at real-time priority (:mod:`lagsym.dnc.priority`),
        so that a loaded computer wakes the sender in time to keep a small
        window busy at a high baud rate.
    """

    baud: int = 9600
    bytesize: int = 7
    parity: str = "even"
    stopbits: float = 2
    flow: str = "xonxoff"
    line_ending: str = "lf"
    leader: str = ""
    trailer: str = ""
    percent: bool = True
    dtr: bool = True
    stall_timeout_s: float = 120.0
    overrun_chars: int = 4
    wait_for_xon: bool = False
    carrier: str = "none"
    buffer_chars: int = 256
    memory_chars: int | None = None
    tv_check: bool = False
    iso_check: bool = False
    realtime: bool = False
    handshake_expected: bool = True

    def __post_init__(self):
        for name, what in _NUMBERS.items():  # True is 1 to Python, never a number of bits or characters to a user
            if isinstance(getattr(self, name), bool):
                raise InputError(f"{what} {str(getattr(self, name)).lower()} is a boolean, not a number")
        if not isinstance(self.baud, int) or not 50 <= self.baud <= 4_000_000:
            raise InputError(f"baud rate {self.baud!r} must be a whole number from 50 to 4000000")
        choice(self.bytesize, (5, 6, 7, 8), "data bits")
        choice(self.parity, tuple(PARITIES), "parity")
        if isinstance(self.stopbits, (int, float)):
            object.__setattr__(self, "stopbits", float(self.stopbits))
        choice(self.stopbits, (1.0, 1.5, 2.0), "stop bits")
        choice(self.flow, FLOW_CONTROLS, "flow control")
        choice(self.line_ending, tuple(LINE_ENDINGS), "end of block")
        for name in ("leader", "trailer"):
            text = getattr(self, name)
            if not isinstance(text, str):
                raise InputError(f"{name} {text!r:.80} must be text")
            if any(ord(c) in (DC1, DC2, DC3, DC4) or ord(c) > 127 for c in text):
                raise InputError(f"{name} {text!r} holds a character the line cannot carry or that steers it")
        choice(self.carrier, CARRIERS, "carrier signal")
        if self.stall_timeout_s != math.inf:
            object.__setattr__(self, "stall_timeout_s", positive(self.stall_timeout_s, "stall timeout (seconds)"))
        if not isinstance(self.buffer_chars, int) or not 0 <= self.buffer_chars <= 1_000_000:
            raise InputError(f"control buffer {self.buffer_chars!r} must be 0 to 1000000 characters")
        if self.memory_chars is not None and (not isinstance(self.memory_chars, int) or self.memory_chars < 1):
            raise InputError(f"control memory {self.memory_chars!r} must be a positive number of characters")
        for name in ("percent", "dtr", "wait_for_xon", "tv_check", "iso_check", "realtime", "handshake_expected"):
            if not isinstance(getattr(self, name), bool):
                raise InputError(f"{name} {getattr(self, name)!r} must be true or false")
        if not isinstance(self.overrun_chars, int) or not 1 <= self.overrun_chars <= 4096:
            raise InputError(f"overrun limit {self.overrun_chars!r} must be 1 to 4096 characters")

    @property
    def stall_text(self) -> str:
        """The stall timeout as messages print it."""
        return "for ever" if self.stall_timeout_s == math.inf else f"{self.stall_timeout_s:g} s"

    @property
    def eol(self) -> str:
        """The end-of-block characters :attr:`line_ending` names.

        Examples
        --------
        >>> LineSettings(line_ending="crlf").eol
        '\\r\\n'
        """
        return LINE_ENDINGS[self.line_ending]

    @property
    def bits_per_char(self) -> float:
        """Start bit, data bits, parity bit and stop bits of one character.

        Examples
        --------
        >>> LineSettings(bytesize=7, parity="even", stopbits=2).bits_per_char
        11.0
        """
        return bits_per_char(self.bytesize, self.parity, self.stopbits)

    @property
    def chars_per_s(self) -> float:
        """The line rate in characters per second.

        Examples
        --------
        >>> LineSettings(baud=9600, bytesize=7, parity="even", stopbits=2).chars_per_s
        872.7272727272727
        """
        return self.baud / self.bits_per_char


CARRIER_LOSS_S = 0.5
"""How long the carrier signal may be down before the line counts as lost: short enough that a lost line is
reported within a second, long enough that a shorter flicker is not taken for a loss."""

# Sources for each profile are in docs/dnc.md.
PROFILES: dict[str, LineSettings] = {
    "fanuc": LineSettings(baud=9600, bytesize=7, parity="even", stopbits=2, flow="xonxoff", line_ending="lf",
                          leader="\x00" * 20, trailer="\x00" * 20, percent=True),
    "haas": LineSettings(baud=9600, bytesize=7, parity="even", stopbits=1, flow="xonxoff", line_ending="crlf",
                         leader="", trailer="", percent=True),
    "heidenhain": LineSettings(baud=9600, bytesize=7, parity="even", stopbits=1, flow="xonxoff", line_ending="crlf",
                               leader="\x00" * 50, trailer="\x03", percent=False),
}


def profile(name: str, **overrides) -> LineSettings:
    """The usual line settings of a control family, with any field overridden.

    Examples
    --------
    >>> profile("haas", baud=19200).line_ending
    'crlf'
    """
    choice(name, tuple(PROFILES), "profile")
    return replace(PROFILES[name], **overrides)


def parse_filler(spec: str) -> str:
    """Read a leader or trailer: a count of NULs (``20``) or items like ``50*NUL,ETX``.

    Examples
    --------
    >>> parse_filler("3"), parse_filler("2*NUL,ETX"), parse_filler("")
    ('\\x00\\x00\\x00', '\\x00\\x00\\x03', '')
    """
    out = []
    for item in (s.strip() for s in spec.split(",") if s.strip()):
        count, _, name = item.rpartition("*")
        if not count and _digits(item):
            count, name = item, "NUL"
        name = name.upper()
        if name not in _FILLERS:
            raise InputError(f"leader/trailer item {item!r}: {name!r} is not one of {', '.join(_FILLERS)}")
        if count and (not _digits(count) or int(count) > 10_000):
            raise InputError(f"leader/trailer item {item!r}: {count!r} is not a count from 0 to 10000")
        out.append(_FILLERS[name] * (int(count) if count else 1))
    return "".join(out)


def _digits(text: str) -> bool:
    """ASCII digits only: ``str.isdigit`` also takes superscripts and other scripts' digits, which int() refuses."""
    return text.isascii() and text.isdigit()


def check_port(name: str, where: str = "--port") -> str:
    """A port name: a device, or a pyserial URL whose host, port number and options are checked.

    Examples
    --------
    >>> check_port("socket://dnc.shop.lan:4001"), check_port("loop://?logging=debug")
    ('socket://dnc.shop.lan:4001', 'loop://?logging=debug')
    >>> check_port("socket://127.0.0.1:99999")
    Traceback (most recent call last):
    ...
    lagsym.errors.InputError: --port 'socket://127.0.0.1:99999': the port number must be 1 to 65535 (socket://HOST:PORT)
    """
    if not isinstance(name, str) or not name.strip() or "\x00" in name:
        raise InputError(f"{where} {name!r}: give a device (/dev/ttyUSB0, COM3) or a URL (socket://host:4001)")
    if "://" not in name:
        return name  # a device: opening it says whether it is there
    scheme, _, rest = name.partition("://")
    scheme = scheme.lower()
    if scheme not in URL_SCHEMES:
        raise InputError(f"{where} {name!r}: {scheme}:// is not a serial URL; the schemes are "
                         f"{', '.join(s + '://' for s in URL_SCHEMES)}")
    if scheme not in _URL_OPTIONS:
        return name
    place, _, query = rest.partition("?")
    if scheme == "loop":
        if place.strip("/"):
            raise InputError(f"{where} {name!r}: loop:// takes no host or path")
    else:
        host, colon, number = place.rstrip("/").rpartition(":")
        if not colon or not host:
            raise InputError(f"{where} {name!r}: give the host and port number ({scheme}://HOST:PORT)")
        if not _digits(number) or not 1 <= int(number) <= 65535:
            raise InputError(f"{where} {name!r}: the port number must be 1 to 65535 ({scheme}://HOST:PORT)")
    for item in filter(None, query.split("&")):
        _url_option(name, where, scheme, *item.partition("=")[::2])
    return name


def _url_option(name: str, where: str, scheme: str, key: str, value: str) -> None:
    known = _URL_OPTIONS[scheme]
    if key not in known:
        raise InputError(f"{where} {name!r}: {key!r} is not an option of {scheme}:// (its options: "
                         f"{', '.join(known)})")
    if key == "logging" and value not in _LOGGING:
        raise InputError(f"{where} {name!r}: logging={value} must be one of {', '.join(_LOGGING)}")
    if key == "timeout":
        try:
            ok = 0 < float(value) <= 3600
        except ValueError:
            ok = False
        if not ok:
            raise InputError(f"{where} {name!r}: timeout={value} must be a number of seconds above 0, up to 3600")
