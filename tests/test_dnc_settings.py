"""Line settings: profiles, their checks, the line rate and leader/trailer specs."""

from __future__ import annotations

import dataclasses

import pytest

from lagsym.dnc import PROFILES, LineSettings, parse_filler, profile
from lagsym.errors import InputError


def test_profiles_fill_in_settings_and_any_can_be_overridden():
    fanuc = profile("fanuc", baud=4800)
    assert (fanuc.baud, fanuc.bytesize, fanuc.parity, fanuc.stopbits, fanuc.flow) == (4800, 7, "even", 2.0, "xonxoff")
    assert PROFILES["heidenhain"].percent is False and PROFILES["heidenhain"].trailer == "\x03"
    assert PROFILES["haas"].line_ending == "crlf"
    with pytest.raises(InputError, match="fanuc, haas, heidenhain"):
        profile("mazak")


def test_settings_are_frozen_and_checked_against_their_choices():
    s = LineSettings()
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.baud = 19200
    with pytest.raises(InputError, match="none, even, odd, mark, space"):
        LineSettings(parity="evn")
    with pytest.raises(InputError, match="xonxoff, rtscts, dtrdsr, none"):
        LineSettings(flow="dtr")
    assert LineSettings(bytesize=8, parity="none", stopbits=1).bits_per_char == 10


def test_leader_and_trailer_specs():
    assert parse_filler("2*NUL,ETX") == "\x00\x00\x03"
    with pytest.raises(InputError, match="NUL"):
        parse_filler("3*BEL")
