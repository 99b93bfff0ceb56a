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
