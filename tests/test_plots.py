"""Outlines of shaped objects in the run plots."""

from __future__ import annotations

import numpy as np
import pytest

from dcsim.api import Shape, ShapeKind
from dcsim.shape_outlines import outline, wireframe

QUARTER_TURN_Z = [0.0, 0.0, 0.5**0.5, 0.5**0.5]
QUARTER_TURN_X = [0.5**0.5, 0.0, 0.0, 0.5**0.5]


def extent(outline: np.ndarray) -> np.ndarray:
    return np.array([outline.min(axis=0), outline.max(axis=0)])


def test_a_box_footprint_is_its_turned_rectangle():
    box = Shape(ShapeKind.BOX, half_extents=[1.0, 2.0, 3.0], orientation=QUARTER_TURN_Z)
    top = outline(box)
    assert len(top) == 4
    np.testing.assert_allclose(extent(top), [[-2.0, -1.0], [2.0, 1.0]], atol=1e-12)
    eighth = Shape(
        ShapeKind.BOX,
        half_extents=[1.0, 1.0, 1.0],
        orientation=[0.0, 0.0, np.sin(np.pi / 8), np.cos(np.pi / 8)],
    )
    assert np.max(np.linalg.norm(outline(eighth), axis=1)) == pytest.approx(2**0.5)
    np.testing.assert_allclose(extent(outline(eighth)), [[-(2**0.5)] * 2, [2**0.5] * 2])


def test_a_cylinder_footprint_is_a_disc_upright_and_a_rectangle_lying_down():
    upright = outline(Shape(ShapeKind.CYLINDER, radius=0.5, height=6.0))
    np.testing.assert_allclose(np.linalg.norm(upright, axis=1), 0.5)
    lying = outline(Shape(ShapeKind.CYLINDER, radius=0.5, height=6.0, orientation=QUARTER_TURN_X))
    np.testing.assert_allclose(extent(lying), [[-0.5, -3.0], [0.5, 3.0]], atol=1e-12)


def test_a_sphere_outline_is_its_circle_in_any_view():
    ball = Shape(ShapeKind.SPHERE, radius=1.5)
    for axes in ((0, 1), (0, 2), (1, 2)):
        np.testing.assert_allclose(np.linalg.norm(outline(ball, axes), axis=1), 1.5)


def test_side_views_project_on_their_own_axes():
    box = Shape(ShapeKind.BOX, half_extents=[1.0, 2.0, 3.0], orientation=QUARTER_TURN_Z)
    np.testing.assert_allclose(extent(outline(box, (0, 2))), [[-2.0, -3.0], [2.0, 3.0]])
    np.testing.assert_allclose(extent(outline(box, (1, 2))), [[-1.0, -3.0], [1.0, 3.0]])


def test_wireframes_lie_on_the_shapes():
    box = Shape(ShapeKind.BOX, half_extents=[1.0, 2.0, 3.0], orientation=QUARTER_TURN_X)
    edges = wireframe(box)
    assert len(edges) == 12
    lengths = sorted(float(np.linalg.norm(e[1] - e[0])) for e in edges)
    np.testing.assert_allclose(lengths, [2.0] * 4 + [4.0] * 4 + [6.0] * 4)
    cylinder = Shape(ShapeKind.CYLINDER, radius=0.5, height=6.0, orientation=QUARTER_TURN_X)
    lines = wireframe(cylinder)
    assert len(lines) == 6  # two end circles, four lines along the side
    points = np.vstack(lines)
    np.testing.assert_allclose(np.hypot(points[:, 0], points[:, 2]), 0.5)
    np.testing.assert_allclose(np.sort(np.unique(np.round(points[:, 1], 9))), [-3.0, 3.0])
    ball = np.vstack(wireframe(Shape(ShapeKind.SPHERE, radius=2.0)))
    np.testing.assert_allclose(np.linalg.norm(ball, axis=1), 2.0)
