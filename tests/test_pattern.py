"""The path pattern: raster rows over the box and the scallop side step."""

from __future__ import annotations

import numpy as np
import pytest

from lagsym.errors import ToolpathError
from lagsym.toolpath import raster_pattern, scallop_stepover


def test_raster_pattern_covers_the_box_with_steps_no_wider_than_asked():
    levels, along = raster_pattern((0, 10, 0, 4), "x", 0.3, 0.7)
    assert levels[0] == 0 and levels[-1] == 4 and np.diff(levels).max() <= 0.3 + 1e-12
    assert along[0] == 0 and along[-1] == 10 and np.diff(along).max() <= 0.7 + 1e-12


def test_scallop_gives_the_side_step():
    assert scallop_stepover(3.0, 0.01) == pytest.approx(2 * np.sqrt(0.06 - 0.0001))
    with pytest.raises(ToolpathError, match="radius"):
        scallop_stepover(1.0, 2.0)
