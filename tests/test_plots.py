"""The trajectory plot's outlines of shaped objects."""

from __future__ import annotations

import numpy as np
import pytest

from dcsim.api import Shape, ShapeKind
from dcsim.plots import _footprint

QUARTER_TURN_Z = [0.0, 0.0, 0.5**0.5, 0.5**0.5]
QUARTER_TURN_X = [0.5**0.5, 0.0, 0.0, 0.5**0.5]


def extent(outline: np.ndarray) -> np.ndarray:
    return np.array([outline.min(axis=0), outline.max(axis=0)])


def test_a_box_footprint_is_its_turned_rectangle():
    box = Shape(ShapeKind.BOX, half_extents=[1.0, 2.0, 3.0], orientation=QUARTER_TURN_Z)
    outline = _footprint(box)
    assert len(outline) == 4
    np.testing.assert_allclose(extent(outline), [[-2.0, -1.0], [2.0, 1.0]], atol=1e-12)
    eighth = Shape(
        ShapeKind.BOX,
        half_extents=[1.0, 1.0, 1.0],
        orientation=[0.0, 0.0, np.sin(np.pi / 8), np.cos(np.pi / 8)],
    )
    assert np.max(np.linalg.norm(_footprint(eighth), axis=1)) == pytest.approx(2**0.5)
    np.testing.assert_allclose(extent(_footprint(eighth)), [[-(2**0.5)] * 2, [2**0.5] * 2])


def test_a_cylinder_footprint_is_a_disc_upright_and_a_rectangle_lying_down():
    upright = _footprint(Shape(ShapeKind.CYLINDER, radius=0.5, height=6.0))
    np.testing.assert_allclose(np.linalg.norm(upright, axis=1), 0.5)
    lying = _footprint(
        Shape(ShapeKind.CYLINDER, radius=0.5, height=6.0, orientation=QUARTER_TURN_X)
    )
    np.testing.assert_allclose(extent(lying), [[-0.5, -3.0], [0.5, 3.0]], atol=1e-12)
