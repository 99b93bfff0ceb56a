"""RS-232 transfer to and from a CNC control: upload, drip feed, resume and receive.

One module per concern, in the order the data goes down the line:

* :mod:`~lagsym.dnc.settings`: :class:`LineSettings` and the usual
  :data:`PROFILES` of each control family;
* :mod:`~lagsym.dnc.blocks`: a program as the blocks a control receives
  (:class:`Program`, :func:`parse_program`) and the framing around them;
* :mod:`~lagsym.dnc.resume`: the modal set-up that resumes a drip feed at a
  block (:func:`resume_setup`);
* :mod:`~lagsym.dnc.transfer`: the bytes a send puts on the line
  (:func:`transfer_segments`) and :func:`send_program`;
* :mod:`~lagsym.dnc.sender`: the sender's pacing, XON/XOFF, hardware signals
  and accounting; :mod:`~lagsym.dnc.results`: what a transfer reports;
* :mod:`~lagsym.dnc.receiver`: :func:`receive_program`;
* :mod:`~lagsym.dnc.server`: ``lagsym dnc serve``, ports that machines call
  (:func:`load_config`, :func:`serve`);
* :mod:`~lagsym.dnc.port`: the serial port itself, the only module in lagsym
  that imports serial.  It loads when a transfer starts, not on import.
"""

from ..machine import LINE_ENDINGS
from .blocks import DC1, DC2, DC3, DC4, ISO_840, Program, check_drip, check_iso, frame, parse_program
from .receiver import receive_program
from .results import LineFault, TransferProgress, TransferResult
from .resume import find_block, resume_setup
from .settings import (CARRIERS, FLOW_CONTROLS, MODES, PARITIES, PROFILES, URL_SCHEMES, LineSettings, check_port,
                       parse_filler, profile)
from .transfer import send_program, transfer_segments

__all__ = [
    "LineSettings",
    "PROFILES",
    "FLOW_CONTROLS",
    "CARRIERS",
    "PARITIES",
    "LINE_ENDINGS",
    "MODES",
    "profile",
    "parse_filler",
    "check_port",
    "URL_SCHEMES",
    "Program",
    "parse_program",
    "frame",
    "check_drip",
    "check_iso",
    "ISO_840",
    "find_block",
    "DC1",
    "DC2",
    "DC3",
    "DC4",
    "resume_setup",
    "TransferProgress",
    "TransferResult",
    "LineFault",
    "transfer_segments",
    "send_program",
    "receive_program",
]
