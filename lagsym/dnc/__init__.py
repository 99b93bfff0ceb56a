"""RS-232 transfer to and from a CNC control: upload, drip feed, resume and receive.

One module per concern, in the order the data goes down the line:

* :mod:`~lagsym.dnc.settings`: :class:`LineSettings` and the usual
  :data:`PROFILES` of each control family;
* :mod:`~lagsym.dnc.blocks`: a program as the blocks a control receives
  (:class:`Program`, :func:`parse_program`) and the framing around them;
* :mod:`~lagsym.dnc.resume`: the modal set-up that resumes a drip feed at a
  block (:func:`resume_setup`);
* :mod:`~lagsym.dnc.transfer`: the bytes a send puts on the line
  (:func:`transfer_segments`), the sender's pacing and XON/XOFF, and
  :func:`send_program` and :func:`receive_program`;
* :mod:`~lagsym.dnc.port`: the serial port itself, the only module in lagsym
  that imports serial.  It loads when a transfer starts, not on import.
"""

from ..machine import LINE_ENDINGS
from .blocks import DC1, DC2, DC3, DC4, Program, frame, parse_program
from .resume import resume_setup
from .settings import FLOW_CONTROLS, MODES, PARITIES, PROFILES, LineSettings, parse_filler, profile
from .transfer import LineFault, TransferProgress, TransferResult, receive_program, send_program, transfer_segments

__all__ = [
    "LineSettings",
    "PROFILES",
    "FLOW_CONTROLS",
    "PARITIES",
    "LINE_ENDINGS",
    "MODES",
    "profile",
    "parse_filler",
    "Program",
    "parse_program",
    "frame",
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

plan_transfer = transfer_segments  # the former name of transfer_segments
