"""The former home of the program blocks and the resume set-up, now in :mod:`lagsym.dnc`."""

from .dnc import DC1, DC2, DC3, DC4, Program, frame, parse_program, resume_setup  # noqa: F401
