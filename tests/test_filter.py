"""Filtering the fine samples of a row to a chordal tolerance."""

from __future__ import annotations

import numpy as np

from lagsym.toolpath import filter_rows


def test_filter_keeps_moves_within_the_tolerance():
    t = np.linspace(0, 10, 201)
    z = np.sin(t)
    keep = filter_rows(t, z, 0.01)
    assert keep[0] == 0 and keep[-1] == 200 and len(keep) < 60
    for i, j in zip(keep[:-1], keep[1:]):
        chord = np.interp(t[i:j + 1], [t[i], t[j]], [z[i], z[j]])
        assert np.abs(chord - z[i:j + 1]).max() <= 0.01


def test_a_move_of_no_length_is_measured_as_a_vertical_move_without_a_warning():
    """Two samples rounded onto one position: the move between them goes straight up.

    The sample above that move by 0.1 is lifted by 0.1; the one inside its
    span lies on it; no divide by zero is warned about.
    """
    import warnings

    from lagsym.toolpath.chordal import move_rises, move_sags

    t = np.array([0.0, 1.0, 1.0, 1.0, 2.0])
    z = np.array([0.0, 0.5, 0.8, 0.9, 0.0])
    keep = np.array([0, 1, 3, 4])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sag, seen = move_sags(t, z, keep, np.zeros(len(z)), 0.0)
        rises = move_rises(t, z, keep)
    assert seen.tolist() == [0.0, 0.0, 0.0]
    assert rises.tolist() == [0.0, 0.0, 0.0]
    z[2] = 1.0  # now above the vertical move from 0.5 to 0.9 by 0.1
    sag, seen = move_sags(t, z, keep, np.zeros(len(z)), 0.0)
    assert seen[1] == z[2] - 0.9 and sag[1] == z[2] - 0.9
