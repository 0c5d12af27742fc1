"""The robot's pose over a run, from its telemetry: base position and attitude, arm links,
the thrusters and how much each fired.

The arm of a manipulator is drawn from its joint angles through dcsim's public robot
model (:meth:`dcsim.robots.manipulator.ManipulatorModel.forward_kinematics`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from dcsim.run.recording import duty_columns
from dcsim.scenario.model import ManipulatorSection, Scenario

_ATTITUDE_COLUMNS = ("qx", "qy", "qz", "qw")


@dataclass(frozen=True)
class RobotPath:
    """The robot's base at every telemetry row.

    Attributes
    ----------
    times : ndarray (N,)
        Row times, s.
    positions : ndarray (N, 3)
        Base position (a manipulator's: its centre of mass), m, world frame.
    attitudes : ndarray (N, 4)
        Base attitude, body to world, unit quaternions ``[x, y, z, w]``.
    """

    times: np.ndarray
    positions: np.ndarray
    attitudes: np.ndarray

    @classmethod
    def from_telemetry(cls, telemetry: Mapping[str, np.ndarray]) -> RobotPath:
        """The path in ``telemetry`` (identity attitude where its columns are absent)."""
        times = np.asarray(telemetry["time"], dtype=float)
        positions = np.column_stack([telemetry[axis] for axis in "xyz"]).astype(float)
        if all(name in telemetry for name in _ATTITUDE_COLUMNS):
            attitudes = np.column_stack([telemetry[name] for name in _ATTITUDE_COLUMNS])
            norms = np.linalg.norm(attitudes, axis=1, keepdims=True)
            attitudes = np.where(norms > 0, attitudes / np.where(norms > 0, norms, 1.0), _IDENTITY)
        else:
            attitudes = np.tile(_IDENTITY, (len(times), 1))
        return cls(times, positions, attitudes)

    def row_at(self, times: np.ndarray) -> np.ndarray:
        """Index of the latest row at or before each of ``times`` (s); the first row before it."""
        rows = np.searchsorted(self.times, np.asarray(times, dtype=float), side="right") - 1
        return np.clip(rows, 0, len(self.times) - 1)

    def rotations(self, rows: np.ndarray | slice = slice(None)) -> Rotation:
        """Body-to-world rotations of the base at ``rows``."""
        return Rotation.from_quat(self.attitudes[rows])


_IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])


def body_axes(path: RobotPath, rows: np.ndarray, length: float) -> np.ndarray:
    """The base's body x, y and z axes drawn from its centre at ``rows``.

    Parameters
    ----------
    path : RobotPath
        The robot's path.
    rows : ndarray (F,) of int
        Telemetry rows.
    length : float
        Length of each axis drawn, m.

    Returns
    -------
    ndarray (3, F, 2, 3)
        For each axis and row: the centre and the axis's tip, m, world frame.
    """
    centres = path.positions[rows]
    matrices = path.rotations(rows).as_matrix()  # (F, 3, 3): columns are the body axes
    tips = centres[None] + length * np.moveaxis(matrices, 2, 0)
    return np.stack([np.broadcast_to(centres, tips.shape), tips], axis=2)


def arm_polylines(
    scenario: Scenario, telemetry: Mapping[str, np.ndarray], path: RobotPath, rows: np.ndarray
) -> np.ndarray | None:
    """The arm of a manipulator at ``rows``: base centre, then DH frame origins 0 … n.

    Parameters
    ----------
    scenario : Scenario
        The run's scenario; its robot's DH table gives the model.
    telemetry : mapping of str to ndarray
        The run's telemetry with ``joint_1`` … ``joint_n`` (rad).
    path : RobotPath
        The base's path in the same telemetry.
    rows : ndarray (F,) of int
        Telemetry rows.

    Returns
    -------
    ndarray (F, n + 2, 3) or None
        Points from the base's centre of mass through the mount and every joint to the
        end effector, m, world frame; None if the robot is not a manipulator or the
        telemetry has no joint columns.
    """
    robot = scenario.robot
    if not isinstance(robot, ManipulatorSection):
        return None
    joints = [f"joint_{i}" for i in range(1, len(robot.links) + 1)]
    if not all(name in telemetry for name in joints):
        return None
    from dcsim.robots.manipulator import manipulator_model  # its compiled core loads on use

    model = manipulator_model(robot.dh_robot())
    angles = np.column_stack([telemetry[name] for name in joints])
    states = np.hstack([path.positions, path.attitudes, angles])[rows]
    return np.stack(
        [np.vstack([state[:3], model.forward_kinematics(state).origins]) for state in states]
    )


@dataclass(frozen=True)
class Thrusters:
    """The base's thrusters and how much each fired at the viewer's frames.

    Attributes
    ----------
    positions : ndarray (N, 3)
        Where each thruster sits, body frame, from the base's centre of mass, m.
    directions : ndarray (N, 3)
        Unit direction of each thruster's force on the base, body frame (its plume leaves
        the other way).
    duty : ndarray (F, N)
        Each thruster's mean duty cycle (fraction of the control period it fired, 0 to 1)
        over the telemetry rows a frame stands for: those after the previous frame's row
        up to its own, so that no firing between frames is lost.
    """

    positions: np.ndarray
    directions: np.ndarray
    duty: np.ndarray

    @classmethod
    def of(
        cls, scenario: Scenario, telemetry: Mapping[str, np.ndarray], rows: np.ndarray
    ) -> Thrusters | None:
        """The thrusters of ``scenario``'s robot with their ``duty_i`` columns in
        ``telemetry`` at the frames' ``rows``; None without thrusters or duty columns."""
        robot = scenario.robot
        thrusters = robot.actuators.thrusters
        if thrusters is None:
            return None
        names = duty_columns(len(thrusters))
        if not all(name in telemetry for name in names):
            return None
        positions = np.array([t.position for t in thrusters], dtype=float)
        directions = np.array([t.direction for t in thrusters], dtype=float)
        directions /= np.linalg.norm(directions, axis=1, keepdims=True)
        duty = np.column_stack([telemetry[name] for name in names]).astype(float)
        return cls(positions, directions, frame_means(np.nan_to_num(duty), rows))


def frame_means(values: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """The mean of ``values`` (R, ...) over the rows each frame stands for: after the
    previous frame's row up to and including its own (``rows``, increasing; the first
    frame's alone)."""
    starts = np.concatenate([[0], np.asarray(rows[:-1]) + 1])
    ends = np.asarray(rows) + 1
    sums = np.add.reduceat(values[: ends[-1]], starts, axis=0)
    return sums / (ends - starts).reshape(-1, *([1] * (values.ndim - 1)))
