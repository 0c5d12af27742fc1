"""``ompl-control`` path planner: the source's 12-DoF spacecraft on OMPL's control layer.

The model is eq. 2 of the kinodynamic RRT course project: a rigid body with
state ``(p, q, v, ω)`` (position m, attitude ``[x, y, z, w]`` body to world, velocity
m/s, angular velocity rad/s, all in the world frame) driven by a force ``F`` and a torque
``τ``::

    ṗ = v,   q̇ = ½ [ω, 0] ⊗ q,   v̇ = F / M (+ Clohessy–Wiltshire terms),   ω̇ = R I⁻¹ Rᵀ τ

The planner's state adds the time ``t`` (s) and the delta-v spent ``Δv`` (m/s): moving
obstacles are checked where they are at the state's own time, and ``max_delta_v`` is a
validity constraint. ``M`` and the principal moments ``I`` are parameters (a path
problem carries neither); the thrust acceleration is the problem's
``max_acceleration`` (else ``force / mass``) and the torque is ``I_max ·
max_angular_acceleration`` (else ``torque``).

Controls (``controls``)
    ``continuous``: a world-frame force and torque, each sampled by OMPL uniformly in a
    cube and scaled back onto the ball of the limit if longer. ``discrete``: the
    source's sets, force ``{+f, −f, 0}`` along the body z axis and torque ``{±τ about
    world x, y or z, 0}``. OMPL has no discrete control space: the control is a real
    pair sampled uniformly in ``[0, 3) × [0, 7)`` and each component is floored to an
    index into its set (:func:`discrete_control`), so every member is equally likely.
Propagation
    ``integrator`` Euler (the source's) or RK4 steps of ``step`` s (the source's Δt =
    0.3 s); OMPL holds each control ``min_steps`` to ``max_steps`` steps. The
    quaternion is renormalised after every step.
Distance
    OMPL 2.0.1's Python bindings never call a Python ``distance``, so every coordinate
    is stored multiplied by the square root of its weight and OMPL's Euclidean distance
    squared is ``w_p‖Δp‖² + w_q‖Δq‖² + w_v‖Δv‖² + w_ω‖Δω‖² + w_t Δt² + w_Δv ΔΔv²``:
    the source's ρ exactly in its position, velocity and rate terms, with
    ``w_q‖Δq‖² = 2 w_q (1 − q₁·q₂)`` in place of ``w_q (1 − |q₁·q₂|)²`` (not a
    Euclidean form). Sampled attitudes are the identity, as in the source, so the term
    only counts a node's own turn.
Sampling
    The source's: positions uniform in the problem's bounds (without bounds, the
    source's box ``[−16, 16] × [−8, 8] × [−25, 25]`` m grown to hold the start and the
    goal), identity attitude, velocity in ``[−5, 5]³`` m/s and angular velocity in
    ``[−2, 2]³`` rad/s (each clipped to the problem's limits), times up to the goal's
    time or ``horizon``. With probability ``goal_bias`` RRT samples a state in the goal
    region instead (OMPL's goal bias; EST and KPIECE1 have none from Python).
Validity
    Inside the bounds, speed, angular rate and delta-v within the limits, and the
    robot's sphere (``robot_radius`` plus the problem's ``safety_margin``) clear of
    every obstacle's TRUE shape (sphere, box, cylinder) where it is at the state's time.
    Each checked sphere is grown by half the distance robot and obstacles can cover in
    one step, so the straight segments between the checked steps are clear too.
Goal
    A state counts as arrived when it is inside the goal region within every tolerance,
    or when a closing manoeuvre (:class:`ClosingManoeuvre`) reaches the goal from it:
    position and velocity cubic in time into the region at the goal's velocity (when
    the goal leaves it free: at the node's velocity, or else at constant acceleration),
    at the goal's time if
    it sets one, else after the shortest duration that keeps the limits; attitude
    turned onto the goal's by a cubic rotation vector (its rate is reported as the
    angular velocity: exact when the turn and the start's spin share an axis), within
    every limit and clear of the obstacles. It is tried from each node within
    ``connect_radius`` of the region that is closer to it than every node tried before,
    in an inertial frame only (it leaves out the Clohessy–Wiltshire terms).
    ``connect_radius = 0`` plans as the source does, by propagation alone.

The solution is every propagation step of the path (and of the closing manoeuvre), with
the force and torque held over each step, so the transfer mission flies it by
feed-forward plus feedback. Each plan runs in a forked worker (``ompl_support``) seeded
from the plugin's generator: the same seed gives the same trajectory. The solve stops at
the first exact solution or when the budget runs out; an approximate solution is
reported as "no path" with how close it came.

Statistics: ``iterations`` (propagations started with a freshly sampled control,
counted in the propagator: RRT's tree-extension attempts, one per iteration),
``nodes_in_tree`` (OMPL's PlannerData vertices, the start included), ``nodes_added``
(vertices but the start: for RRT the attempts that made a node; KPIECE1 adds a node at
every step of a propagation), ``nodes_expanded`` (vertices with at least one child, from
PlannerData's edges), ``propagation_steps``, ``validity_checks``, ``closing_attempts``
and ``exact``. The source's "1099 of 1151 nodes expanded" compares with RRT's
``nodes_added`` of ``iterations``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from dcsim_plugins.path_planners.obstacle_field import (
    ObstacleField,
    endpoint_refusal,
)
from dcsim_plugins.path_planners.ompl.closing_manoeuvre import Closing, ClosingManoeuvre
from dcsim_plugins.path_planners.ompl.rigid_body import (
    DIMENSION,
    DV,
    Model,
    P,
    Q,
    T,
    V,
    W,
    state_vector,
)
from dcsim_plugins.path_planners.ompl.support import in_worker, seed_ompl
from ompl import base as ob
from ompl import control as oc
from pydantic import field_validator

from dcsim.api import (
    FrameKind,
    NoPath,
    PathPlanner,
    PathPlannerParams,
    PathProblem,
    Trajectory,
    hookimpl,
    quantity,
    quaternion_conjugate,
    quaternion_multiply,
    rotate,
    rotation_vector,
)

SOURCE_BOX = (np.array([-16.0, -8.0, -25.0]), np.array([16.0, 8.0, 25.0]))
"""The source's position sampling box, m."""
SOURCE_SPEED, SOURCE_RATE = 5.0, 2.0
"""The source's velocity (m/s) and angular-velocity (rad/s) sampling half-ranges."""
_RESERVE = 0.05  # s of the budget kept for expanding and returning the solution


class OmplControlParams(PathPlannerParams):
    """Parameters of :class:`OmplControlPlanner`."""

    planner: Literal["rrt", "est", "kpiece"] = quantity(
        "rrt", description="OMPL control planner: RRT, EST or KPIECE1 (those that construct)."
    )
    controls: Literal["continuous", "discrete"] = quantity(
        "continuous", description="World force and torque within the limits, or the source's sets."
    )
    integrator: Literal["euler", "rk4"] = quantity(
        "euler", description="Integration of eq. 2 over one step: the source's Euler, or RK4."
    )
    step: float = quantity(0.3, unit="s", gt=0, description="Propagation step (the source's Δt).")
    min_steps: int = quantity(1, ge=1, le=1000, description="Fewest steps a control is held.")
    max_steps: int = quantity(20, ge=1, le=1000, description="Most steps a control is held.")
    position_weight: float = quantity(0.05, unit="1/m^2", gt=0, description="ρ weight on ‖Δp‖².")
    attitude_weight: float = quantity(5.0, gt=0, description="ρ weight on the attitude term.")
    velocity_weight: float = quantity(0.3, unit="s^2/m^2", gt=0, description="ρ weight on ‖Δv‖².")
    rate_weight: float = quantity(0.5, unit="s^2", gt=0, description="ρ weight on ‖Δω‖².")
    time_weight: float = quantity(1e-6, unit="1/s^2", gt=0, description="Distance weight on Δt².")
    delta_v_weight: float = quantity(
        1e-6,
        unit="s^2/m^2",
        gt=0,
        description="Distance weight on the difference of delta-v spent.",
    )
    goal_bias: float = quantity(
        0.05, ge=0, le=1, description="Probability of sampling the goal region (RRT)."
    )
    connect_radius: float = quantity(
        50.0,
        unit="m",
        ge=0,
        description="Distance to the goal region within which a closing "
        "manoeuvre is tried; 0 plans by propagation alone, as the source.",
    )
    horizon: float = quantity(
        600.0, unit="s", gt=0, description="Span of sampled times when the goal sets none."
    )
    mass: float = quantity(1.0, unit="kg", gt=0, description="Mass M of eq. 2.")
    inertia: tuple[float, float, float] = quantity(
        (0.1, 0.1, 0.1), unit="kg m^2", description="Principal moments of inertia I of eq. 2."
    )
    force: float = quantity(
        0.5, unit="N", gt=0, description="Thrust when the problem's max_acceleration is inf."
    )
    torque: float = quantity(
        0.01, unit="N m", gt=0, description="Torque when max_angular_acceleration is inf."
    )

    @field_validator("inertia")
    @classmethod
    def _positive_moments(cls, value: tuple[float, float, float]) -> tuple[float, float, float]:
        """Every principal moment of inertia must be positive."""
        if min(value) <= 0:
            raise ValueError(f"every principal moment must be positive, got {value}")
        return value


def make_model(params: OmplControlParams, problem: PathProblem) -> Model:
    """The model of ``params`` with the thrust and torque the problem's limits allow."""
    acceleration = problem.max_acceleration
    if not math.isfinite(acceleration):
        acceleration = params.force / params.mass
    torque = params.torque
    if math.isfinite(problem.max_angular_acceleration):
        torque = max(params.inertia) * problem.max_angular_acceleration
    frame = problem.frame
    n = frame.mean_motion if frame.kind is FrameKind.CLOHESSY_WILTSHIRE else 0.0
    return Model(
        acceleration,
        torque,
        params.mass,
        tuple(params.inertia),
        params.controls == "discrete",
        params.integrator == "rk4",
        n,
    )


# ------------------------------------------------------------------ validity


class StateCheck:
    """Whether a state vector is allowed: in bounds, within the limits, clear of obstacles.

    Parameters
    ----------
    problem : PathProblem
        Bounds, limits, robot radius and obstacles.
    field : ObstacleField
        The obstacles, with the robot radius and the safety margin.
    model : Model
        For the largest speed change within one step.
    step : float
        Propagation step, s.
    """

    def __init__(
        self, problem: PathProblem, field: ObstacleField, model: Model, step: float
    ) -> None:
        bounds = problem.bounds
        self.lower = (-math.inf,) * 3 if bounds is None else tuple(map(float, bounds.lower))
        self.upper = (math.inf,) * 3 if bounds is None else tuple(map(float, bounds.upper))
        self.speed2 = problem.max_speed**2 * (1 + 1e-9)
        self.rate2 = problem.max_angular_rate**2
        self.delta_v = problem.max_delta_v
        self.field = field
        self.half_step = 0.5 * step
        self.sweep = field.max_obstacle_speed + model.acceleration * step
        self.checks = 0

    def __call__(self, x: list[float]) -> bool:
        """Whether the state vector ``x`` is valid."""
        self.checks += 1
        px, py, pz = x[0], x[1], x[2]
        lo, hi = self.lower, self.upper
        if not (lo[0] <= px <= hi[0] and lo[1] <= py <= hi[1] and lo[2] <= pz <= hi[2]):
            return False
        speed2 = x[7] * x[7] + x[8] * x[8] + x[9] * x[9]
        if speed2 > self.speed2 or x[10] ** 2 + x[11] ** 2 + x[12] ** 2 > self.rate2:
            return False
        if x[DV] > self.delta_v:
            return False
        margin = self.half_step * (math.sqrt(speed2) + self.sweep)
        return self.field.clear(px, py, pz, x[T], margin)

    def all_valid(self, states: np.ndarray) -> bool:
        """Whether every row of ``states`` (k, 15) is a valid state vector."""
        positions = states[:, P]
        if np.any(positions < self.lower) or np.any(positions > self.upper):
            return False
        speeds = np.linalg.norm(states[:, V], axis=1)
        if np.any(speeds**2 > self.speed2) or np.any(states[:, DV] > self.delta_v):
            return False
        if np.any(np.einsum("ij,ij->i", states[:, W], states[:, W]) > self.rate2):
            return False
        margins = self.half_step * (speeds + self.sweep)
        return self.field.clear_path(positions, states[:, T], margins)


# ------------------------------------------------------------------ the closing manoeuvre


# ------------------------------------------------------------------ OMPL


class Coordinates:
    """State vectors to OMPL's weight-scaled coordinates and back.

    Parameters
    ----------
    params : OmplControlParams
        The distance weights.
    """

    def __init__(self, params: OmplControlParams) -> None:
        weights = (
            [params.position_weight] * 3
            + [params.attitude_weight] * 4
            + [params.velocity_weight] * 3
            + [params.rate_weight] * 3
            + [params.time_weight, params.delta_v_weight]
        )
        self.scale = [math.sqrt(w) for w in weights]
        self.inverse = [1.0 / s for s in self.scale]
        self.indices = range(DIMENSION)

    def read(self, state: Any) -> list[float]:
        """The state vector of an OMPL state."""
        inverse = self.inverse
        return [state[k] * inverse[k] for k in self.indices]

    def write(self, x: list[float], out: Any) -> None:
        """Store the state vector ``x`` into the OMPL state ``out``."""
        scale = self.scale
        for k in self.indices:
            out[k] = x[k] * scale[k]


def sampling_ranges(
    params: OmplControlParams, problem: PathProblem
) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper sampling bounds of the state vector (see the module docstring)."""
    if problem.bounds is not None:
        lower, upper = np.asarray(problem.bounds.lower), np.asarray(problem.bounds.upper)
    else:
        goal_extent = problem.goal.tolerance if problem.goal.half_extents is None else 0.0
        corners = [
            problem.start.position,
            problem.goal.position - goal_extent,
            problem.goal.position + goal_extent,
        ]
        if problem.goal.half_extents is not None:
            corners += [
                problem.goal.position - problem.goal.half_extents,
                problem.goal.position + problem.goal.half_extents,
            ]
        lower = np.minimum.reduce([SOURCE_BOX[0], *corners]) - 1.0
        upper = np.maximum.reduce([SOURCE_BOX[1], *corners]) + 1.0
    speed = min(SOURCE_SPEED, problem.max_speed)
    rate = min(SOURCE_RATE, problem.max_angular_rate)
    t0 = problem.start.time
    t1 = problem.goal.time if problem.goal.time is not None else t0 + params.horizon
    spend = min(problem.max_delta_v, 100.0)
    low = [*lower, 0.0, 0.0, 0.0, 1.0, -speed, -speed, -speed, -rate, -rate, -rate, t0, 0.0]
    high = [
        *upper,
        0.0,
        0.0,
        0.0,
        1.0,
        speed,
        speed,
        speed,
        rate,
        rate,
        rate,
        max(t1, t0 + 1),
        spend,
    ]
    return np.array(low, dtype=float), np.array(high, dtype=float)


class Goal(ob.GoalSampleableRegion):
    """The goal region for OMPL: distance 0 when arrived (see the module docstring).

    Parameters
    ----------
    si : ompl.control.SpaceInformation
        The planning space.
    problem : PathProblem
        The goal region.
    coordinates : Coordinates
        To read OMPL states.
    closing : ClosingManoeuvre
        Tried within ``connect_radius`` of the region.
    connect_radius : float
        m.
    rng : numpy.random.Generator
        For goal samples.
    ranges : tuple of ndarray
        The sampling ranges (for a goal sample's time).
    """

    def __init__(
        self,
        si: Any,
        problem: PathProblem,
        coordinates: Coordinates,
        closing: ClosingManoeuvre,
        connect_radius: float,
        rng: np.random.Generator,
        ranges: tuple[np.ndarray, np.ndarray],
    ) -> None:
        super().__init__(si)
        self.setThreshold(1e-9)
        self.region, self.coordinates, self.closing = problem.goal, coordinates, closing
        self.connect_radius, self.rng, self.ranges = connect_radius, rng, ranges
        self.closings: dict[tuple[float, ...], Closing] = {}
        self.best_gap = math.inf

    def distanceGoal(self, state: Any) -> float:  # noqa: N802 (OMPL's name)
        """0 when ``state`` has arrived, else its distance to the goal region (m, +1)."""
        x = self.coordinates.read(state)
        gap = _region_gap(self.region, x[0], x[1], x[2])
        if gap == 0.0 and _within_tolerances(self.region, x):
            return 0.0
        if gap <= min(self.connect_radius, self.best_gap):
            self.best_gap = gap
            closing = self.closing(x)
            if closing is not None:
                self.closings[tuple(x)] = closing
                return 0.0
        return gap + 1.0

    def sampleGoal(self, state: Any) -> None:  # noqa: N802 (OMPL's name)
        """A state in the goal region: at the goal's velocity, attitude (or the identity)
        and time (or a sampled one), at rest in rotation."""
        region, rng = self.region, self.rng
        if region.half_extents is None:
            direction = rng.normal(size=3)
            offset = direction / max(float(np.linalg.norm(direction)), 1e-12)
            offset *= region.tolerance * rng.uniform() ** (1 / 3)
        else:
            offset = rng.uniform(-1.0, 1.0, 3) * region.half_extents
        attitude = (0.0, 0.0, 0.0, 1.0) if region.attitude is None else region.attitude
        low, high = self.ranges
        t = region.time if region.time is not None else rng.uniform(low[T], high[T])
        x = [*(region.position + offset), *attitude, *region.velocity, 0.0, 0.0, 0.0, t, 0.0]
        self.coordinates.write([float(v) for v in x], state)

    def maxSampleCount(self) -> int:  # noqa: N802 (OMPL's name)
        """Unlimited goal samples."""
        return 1 << 30


def _region_gap(region: Any, x: float, y: float, z: float) -> float:
    """Distance (m) from a point to a goal region's position set (0 inside)."""
    dx, dy, dz = x - region.position[0], y - region.position[1], z - region.position[2]
    if region.half_extents is None:
        return max(0.0, math.sqrt(dx * dx + dy * dy + dz * dz) - region.tolerance)
    h = region.half_extents
    ex, ey, ez = max(abs(dx) - h[0], 0.0), max(abs(dy) - h[1], 0.0), max(abs(dz) - h[2], 0.0)
    return math.sqrt(ex * ex + ey * ey + ez * ez)


def _within_tolerances(region: Any, x: list[float]) -> bool:
    """Whether the state vector ``x`` meets the region's velocity, time and attitude
    tolerances (its position is inside)."""
    if math.isfinite(region.velocity_tolerance):
        dv = math.dist(x[7:10], region.velocity)
        if dv > region.velocity_tolerance:
            return False
    if region.time is not None and abs(x[T] - region.time) > region.time_tolerance:
        return False
    if region.attitude is None:
        return True
    error = quaternion_multiply(np.asarray(x[3:7]), quaternion_conjugate(region.attitude))
    return float(np.linalg.norm(rotation_vector(error))) <= region.attitude_tolerance


class Projection(ob.ProjectionEvaluator):
    """KPIECE1's and EST's projection: the position, in OMPL's scaled coordinates."""

    def getDimension(self) -> int:  # noqa: N802 (OMPL's name)
        """Three: the position."""
        return 3

    def project(self, state: Any, projection: Any) -> None:
        """Copy the scaled position into ``projection``."""
        projection[0], projection[1], projection[2] = state[0], state[1], state[2]


class Counters:
    """Counts of what the planner did (see the module docstring)."""

    def __init__(self) -> None:
        self.steps = 0
        self.iterations = 0
        self.last_control: tuple[float, ...] = ()


@dataclass(frozen=True)
class Solution:
    """What a worker sends back.

    Attributes
    ----------
    states : ndarray (N, 15)
        State vectors at every step, the start's first.
    accelerations, angular_accelerations : ndarray (N − 1, 3)
        Thrust acceleration (m/s²) and angular acceleration (rad/s²) over each step.
    torques : ndarray (N − 1, 3)
        Torque over each step, N·m (world).
    exact : bool
        Whether the path arrives.
    gap : float
        Distance of the closest state from the goal region, m (0 when exact).
    statistics : dict
        See the module docstring.
    """

    states: np.ndarray
    accelerations: np.ndarray
    torques: np.ndarray
    exact: bool
    gap: float
    statistics: dict[str, float]


_PLANNERS = {"rrt": oc.RRT, "est": oc.EST, "kpiece": oc.KPIECE1}


class Setup:
    """OMPL's control setup of one plan: spaces, propagator, validity, goal and planner.

    Parameters
    ----------
    params : OmplControlParams
        The planner's parameters.
    problem : PathProblem
        The problem.
    rng : numpy.random.Generator
        For goal samples.
    """

    def __init__(self, params: OmplControlParams, problem: PathProblem, rng: Any) -> None:
        self.params, self.problem = params, problem
        self.model = make_model(params, problem)
        self.field = ObstacleField(problem)
        self.check = StateCheck(problem, self.field, self.model, params.step)
        self.coordinates = Coordinates(params)
        self.counters = Counters()
        ranges = sampling_ranges(params, problem)
        space = ob.RealVectorStateSpace(DIMENSION)
        bounds = ob.RealVectorBounds(DIMENSION)
        for k, (lo, hi, s) in enumerate(zip(*ranges, self.coordinates.scale, strict=True)):
            bounds.setLow(k, float(lo * s))
            bounds.setHigh(k, float(hi * s))
        space.setBounds(bounds)
        controls = oc.RealVectorControlSpace(space, self.model.control_dimension)
        control_bounds = ob.RealVectorBounds(self.model.control_dimension)
        for k, (lo, hi) in enumerate(zip(*self.model.control_bounds(), strict=True)):
            control_bounds.setLow(k, lo)
            control_bounds.setHigh(k, hi)
        controls.setBounds(control_bounds)
        self.setup = oc.SimpleSetup(controls)
        self.si = self.setup.getSpaceInformation()
        self.setup.setStatePropagator(self.propagate)
        self.setup.setStateValidityChecker(self.valid)
        self.si.setPropagationStepSize(params.step)
        self.si.setMinMaxControlDuration(params.min_steps, max(params.min_steps, params.max_steps))
        start = self.si.allocState()
        self.coordinates.write(state_vector(problem), start)
        self.setup.setStartState(start)
        self.closing = ClosingManoeuvre(problem, self.check, self.model, params.step)
        self.goal = Goal(
            self.si, problem, self.coordinates, self.closing, params.connect_radius, rng, ranges
        )
        self.setup.setGoal(self.goal)
        if params.planner != "rrt":
            self.projection = Projection(space)
            space.registerDefaultProjection(self.projection)
        self.planner = _PLANNERS[params.planner](self.si)
        if params.planner == "rrt":
            self.planner.setGoalBias(params.goal_bias)
        self.setup.setPlanner(self.planner)
        self.space = space
        self.setup.setup()

    def control(self, control: Any) -> tuple[float, ...]:
        """The real control vector of an OMPL control."""
        return tuple(control[k] for k in range(self.model.control_dimension))

    def propagate(self, state: Any, control: Any, duration: float, out: Any) -> None:
        """OMPL's state propagator: one step of ``duration`` s (eq. 2)."""
        counters = self.counters
        counters.steps += 1
        u = self.control(control)
        if u != counters.last_control:
            counters.iterations += 1
            counters.last_control = u
        coordinates = self.coordinates
        coordinates.write(self.model.step(coordinates.read(state), u, duration), out)

    def valid(self, state: Any) -> bool:
        """OMPL's validity checker."""
        return self.check(self.coordinates.read(state))

    def solve(self, deadline: float) -> Solution:
        """Plan until an exact solution or ``deadline`` (``time.monotonic()``)."""
        stop = deadline - _RESERVE
        self.setup.solve(ob.PlannerTerminationCondition(lambda: time.monotonic() >= stop))
        exact = bool(self.setup.haveExactSolutionPath())
        if not self.setup.haveSolutionPath():
            empty = np.zeros((0, 3))
            start = np.array([state_vector(self.problem)])
            gap = _region_gap(self.problem.goal, *start[0, :3])
            return Solution(start, empty, empty, False, gap, self.statistics(exact))
        states, accelerations, torques = self.expand(self.setup.getSolutionPath())
        gap = 0.0 if exact else _region_gap(self.problem.goal, *states[-1, :3])
        return Solution(states, accelerations, torques, exact, gap, self.statistics(exact))

    def expand(self, path: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every step of the solution path (re-propagated from its nodes exactly as OMPL
        propagated them), then the closing manoeuvre of its last node, if it has one:
        state vectors, thrust accelerations and torques."""
        read, step, model = self.coordinates.read, self.params.step, self.model
        scratch = self.si.allocState()
        states, accelerations, torques = [read(path.getState(0))], [], []
        for i in range(path.getControlCount()):
            u = self.control(path.getControl(i))
            count = round(path.getControlDuration(i) / step)
            self.si.copyState(scratch, path.getState(i))
            for _ in range(count):
                wrench = model.wrench(u, read(scratch)[3:7])
                self.coordinates.write(model.step(read(scratch), u, step), scratch)
                states.append(read(scratch))
                accelerations.append(wrench[:3])
                torques.append(wrench[3:])
        closing = self.goal.closings.get(tuple(states[-1]))
        if closing is not None:
            states.extend(closing.states[1:].tolist())
            accelerations.extend(closing.accelerations.tolist())
            torques.extend(self._torques(closing))
        return (
            np.array(states),
            np.array(accelerations).reshape(-1, 3),
            np.array(torques).reshape(-1, 3),
        )

    def _torques(self, closing: Closing) -> list[list[float]]:
        """World torques (N·m) that give a closing manoeuvre's angular accelerations:
        ``R I Rᵀ ω̇`` at the attitude at the start of each step."""
        inertia = np.diag(self.model.inertia)
        out = []
        for q, alpha in zip(closing.states[:-1, Q], closing.angular_accelerations, strict=True):
            rotation = rotate(q, np.eye(3)).T  # body to world
            out.append((rotation @ inertia @ rotation.T @ alpha).tolist())
        return out

    def statistics(self, exact: bool) -> dict[str, float]:
        """The planner's figures (see the module docstring)."""
        data = ob.PlannerData(self.si)
        self.planner.getPlannerData(data)
        vertices = data.numVertices()
        expanded = sum(1 for i in range(vertices) if data.getEdges(i))
        return {
            "iterations": float(self.counters.iterations),
            "nodes_in_tree": float(vertices),
            "nodes_added": float(max(vertices - 1, 0)),
            "nodes_expanded": float(expanded),
            "propagation_steps": float(self.counters.steps),
            "validity_checks": float(self.check.checks),
            "closing_attempts": float(self.closing.attempts),
            "exact": float(exact),
        }


def solve(params: OmplControlParams, problem: PathProblem, seed: int, deadline: float) -> Solution:
    """Seed OMPL, set the problem up and plan until ``deadline``; run in a fresh worker."""
    seed_ompl(seed)
    return Setup(params, problem, np.random.default_rng(seed)).solve(deadline)


def to_trajectory(solution: Solution, mass: float) -> Trajectory:
    """The solution as a Trajectory: every step, with its force (N) and torque (N·m)."""
    states = solution.states
    positions = states[:, P]
    delta_v = float(np.linalg.norm(np.diff(states[:, V], axis=0), axis=1).sum())
    return Trajectory(
        times=states[:, T],
        positions=positions,
        velocities=states[:, V],
        attitudes=states[:, Q],
        angular_velocities=states[:, W],
        forces=mass * solution.accelerations,
        torques=solution.torques,
        delta_v=max(delta_v, float(states[-1, DV])),
        length=float(np.linalg.norm(np.diff(positions, axis=0), axis=1).sum()),
        duration=float(states[-1, T] - states[0, T]),
        statistics=solution.statistics,
    )


class OmplControlPlanner(PathPlanner):
    """Kinodynamic planning of the source's 12-DoF rigid spacecraft with OMPL's control layer."""

    name = "ompl-control"
    summary = (
        "Kinodynamic RRT/EST/KPIECE1 (OMPL) of the 12-DoF rigid body of eq. 2; "
        "moving obstacles checked at each state's time"
    )
    Params = OmplControlParams
    params: OmplControlParams

    def plan(self, problem: PathProblem) -> Trajectory | NoPath:
        """Plan from the start state into the goal region by ``problem.due()``."""
        deadline = problem.due()
        budget = deadline - time.monotonic()  # the deadline, not time_budget, may govern
        refusal = endpoint_refusal(problem, ObstacleField(problem))
        if refusal is not None:
            return refusal
        seed = int(self.rng.integers(1, 2**31 - 1))
        solution = in_worker(solve, (self.params, problem, seed, deadline), deadline)
        if solution is None:
            return NoPath(f"the planner gave no answer within the {budget:.3g} s budget")
        if not solution.exact:
            iterations = solution.statistics["iterations"]
            return NoPath(
                f"no path within the {budget:.3g} s budget: after {iterations:.0f} "
                f"iterations the closest state is {solution.gap:.2f} m from the goal region"
            )
        return to_trajectory(solution, self.params.mass)


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the OMPL control path planner."""
    return [OmplControlPlanner]
