"""Triangle meshes of the convex shapes the viewer draws solid: spheres, boxes, cylinders."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull

from dcsim.messages import Shape
from dcsim.report.outlines import surface_points


@dataclass(frozen=True)
class Mesh:
    """A closed triangle mesh about a body's centre.

    Attributes
    ----------
    vertices : ndarray (V, 3)
        Vertex positions relative to the body's centre, m (world axes for objects, whose
        orientation is fixed; body axes for the robot's base).
    triangles : ndarray (T, 3) of int
        Vertex indices of each triangle.
    """

    vertices: np.ndarray
    triangles: np.ndarray


def shape_mesh(shape: Shape) -> Mesh:
    """The surface of ``shape`` as triangles (the hull of its surface points), m.

    Parameters
    ----------
    shape : Shape
        A sphere, a box or a cylinder, its orientation applied.
    """
    points = surface_points(shape)
    return Mesh(points, ConvexHull(points).simplices.astype(int))
