"""Outlines of object shapes for pictures: flat outlines in a view and 3-D wireframes.

Every function works about the shape's centre, in world axes (the shape's orientation
applied); add the object's position to place it. The run plots of every mission draw
obstacles with these.
"""

from __future__ import annotations

import itertools

import numpy as np
from scipy.spatial import ConvexHull

from dcsim.geometry import rotate
from dcsim.messages import Shape, ShapeKind

CIRCLE_POINTS = 48
"""Points on each circle drawn (sphere outlines, cylinder ends)."""

_BOX_EDGES = [
    (a, b)
    for a, b in itertools.combinations(range(8), 2)
    if bin(a ^ b).count("1") == 1  # corners that differ in one coordinate share an edge
]


def outline(shape: Shape, axes: tuple[int, int] = (0, 1)) -> np.ndarray:
    """The shape's outline seen along the third axis: its projection's boundary (M, 2), m.

    Parameters
    ----------
    shape : Shape
        A sphere, a box or a cylinder.
    axes : tuple of int
        The world axes of the view, e.g. ``(0, 1)`` for the top view (x-y), ``(0, 2)``
        for x-z.

    Returns
    -------
    ndarray (M, 2)
        A closed convex polygon about the centre (first point not repeated).
    """
    if shape.kind is ShapeKind.SPHERE:
        return shape.radius * _unit_circle()
    points = _hull_points(shape)[:, list(axes)]
    return points[ConvexHull(points).vertices]


def wireframe(shape: Shape) -> list[np.ndarray]:
    """Polylines (each (K, 3), m) that draw the shape in 3-D about its centre.

    A sphere: three great circles through its poles and three parallels; a box: its twelve edges; a
    cylinder: its two end circles and four lines along its side.
    """
    if shape.kind is ShapeKind.SPHERE:
        return _sphere_wireframe(shape.radius)
    if shape.kind is ShapeKind.BOX:
        corners = _hull_points(shape)
        return [corners[[a, b]] for a, b in _BOX_EDGES]
    ends = _hull_points(shape).reshape(2, CIRCLE_POINTS, 3)
    rings = [np.vstack([end, end[:1]]) for end in ends]
    sides = [ends[:, k] for k in range(0, CIRCLE_POINTS, CIRCLE_POINTS // 4)]
    return rings + sides


def _hull_points(shape: Shape) -> np.ndarray:
    """A box's 8 corners, or a cylinder's two end circles (bottom then top), in world axes."""
    if shape.kind is ShapeKind.BOX:
        body = np.array(list(itertools.product(*((-h, h) for h in shape.half_extents))))
    else:
        ring = shape.radius * _unit_circle()
        half = 0.5 * shape.height
        body = np.vstack([np.column_stack([ring, np.full(len(ring), z)]) for z in (-half, half)])
    return rotate(shape.orientation, body)


def _sphere_wireframe(radius: float) -> list[np.ndarray]:
    circle = np.vstack([_unit_circle(), _unit_circle()[:1]])
    lines = []
    for azimuth in np.arange(3) * np.pi / 3:  # great circles through the poles
        direction = np.array([np.cos(azimuth), np.sin(azimuth)])
        lines.append(radius * np.column_stack([np.outer(circle[:, 0], direction), circle[:, 1]]))
    for height in (-0.5, 0.0, 0.5):  # parallels
        ring = np.sqrt(1.0 - height**2) * circle
        lines.append(radius * np.column_stack([ring, np.full(len(ring), height)]))
    return lines


def _unit_circle() -> np.ndarray:
    angles = np.linspace(0.0, 2.0 * np.pi, CIRCLE_POINTS, endpoint=False)
    return np.column_stack([np.cos(angles), np.sin(angles)])


SPHERE_POINTS = 162
"""Points spread over a sphere by :func:`surface_points` (a golden-angle spiral)."""


def surface_points(shape: Shape) -> np.ndarray:
    """Points on the shape's surface whose convex hull is the shape (K, 3), m.

    A box's 8 corners, a cylinder's two end circles (bottom then top), or
    :data:`SPHERE_POINTS` points spread evenly over a sphere; about the shape's centre,
    in world axes (the shape's orientation applied). Solid pictures triangulate their
    hull.
    """
    if shape.kind is not ShapeKind.SPHERE:
        return _hull_points(shape)
    index = np.arange(SPHERE_POINTS) + 0.5
    height = 1.0 - 2.0 * index / SPHERE_POINTS
    azimuth = np.pi * (3.0 - np.sqrt(5.0)) * index
    ring = np.sqrt(1.0 - height**2)
    return shape.radius * np.column_stack([ring * np.cos(azimuth), ring * np.sin(azimuth), height])
