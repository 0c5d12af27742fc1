"""The Q-learning planner's environment: a 3-D grid of end-effector cells with the
the space manipulator thesis's actions, constraints and rewards (§5.5.1), precomputed per problem.

Cells are cubes of side ``cell_size`` centred on the lattice through the end effector's
start; the grid spans the box holding the start cell and the target's cell plus
``margin`` cells on every side. Six actions move one cell along ±x, ±y, ±z (Algorithm
5.1); an action that would leave the grid leaves the end effector where it is.

The arm's state at a cell is the inverse kinematics of its centre with the base's
attitude held and the robot's centre of mass fixed (the base translates freely, as
under partial base control), solved by Newton's method from the start's configuration
for every cell alike: a cell's state, and so its rewards, never depend on the path that
led there. The Newton steps take the least joint motion, which resolves the arm's
redundancy towards the start configuration. A cell is *terminal* when that solution
fails, when a joint lies beyond ``joint_limit`` (wrapped to ±180°), when det(J Jᵀ) of
the position Jacobian is at most ``singular_det`` (eq. 3.14), or when the target lies
beyond ``sight_limit`` of the base's facing side (the side facing the target at the
start). The base's displacement criterion (at most ``base_ratio`` of the end effector's
displacement from the start) is not terminal; missing it costs ``base_penalty``.

Entering a cell pays ``target_reward`` (the target's cell, which ends the episode),
``terminal_reward`` (a terminal cell, which ends it too) or ``step_reward`` (plus
``base_penalty`` when the base criterion fails there). Everything a step needs is in
the arrays ``next_cell`` and ``reward`` (cells × actions) and ``ends`` (cells), so
neither training nor the exact solver calls the model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dcsim_plugins.path_planners.deadline import check

from dcsim.api import PathProblem, facing_axis, sight_angle

ACTIONS = np.array([[0, 0, 1], [0, 0, -1], [0, -1, 0], [0, 1, 0], [1, 0, 0], [-1, 0, 0]], dtype=int)
"""Algorithm 5.1's actions in its order: upward, downward, rightward, leftward,
frontward, backward (cell index steps along x, y, z)."""


@dataclass(frozen=True)
class CellRules:
    """The environment's constants (the planner's parameters).

    Attributes
    ----------
    cell_size : float
        Cell side, m.
    margin : int
        Cells added on every side of the box holding the start and target cells.
    joint_limit, sight_limit : float
        Largest joint angle magnitude and sight angle, rad.
    singular_det : float
        ``det(J Jᵀ)`` of the position Jacobian at or below which a cell is singular, m⁶.
    base_ratio : float
        Largest base displacement as a fraction of the end effector's.
    target_reward, terminal_reward, step_reward, base_penalty : float
        Rewards (see the module).
    max_cells : int
        Most cells a grid may have (a larger one is refused before anything is built).
    facing_axis : tuple of float or None
        Base-frame direction of the side that must face the target; None: the base axis
        nearest the target's direction at the start (as the reach mission judges it).
    """

    cell_size: float = 0.05
    margin: int = 2
    joint_limit: float = np.radians(90.0)
    sight_limit: float = np.radians(60.0)
    singular_det: float = 1e-3
    base_ratio: float = 0.5
    target_reward: float = 100.0
    terminal_reward: float = -100.0
    step_reward: float = -1.0
    base_penalty: float = -1.0
    max_cells: int = 200_000
    facing_axis: tuple[float, float, float] | None = None


@dataclass(frozen=True)
class CellEnvironment:
    """One problem's grid, per-cell states and transition and reward tables.

    Attributes
    ----------
    shape : tuple of int
        Cells along x, y, z.
    origin : ndarray (3,)
        Centre of cell (0, 0, 0), world frame, m.
    cell_size : float
        m.
    start, target : int
        Flat indices of the start cell and the target's cell.
    next_cell : ndarray (cells, 6) of int
        Cell reached by each action.
    reward : ndarray (cells, 6)
        Reward of each action.
    ends : ndarray (cells,) of bool
        Whether entering the cell ends an episode (target or terminal).
    terminal : ndarray (cells,) of bool
        Terminal cells (a constraint broken); ``reasons`` says which.
    reasons : tuple of str
        Per cell: "" or the constraint it breaks.
    joints : ndarray (cells, n)
        Joint angles at each cell's centre, rad (NaN where inverse kinematics failed).
    base_positions : ndarray (cells, 3)
        Base centre of mass at each cell, m.
    det_jjt, sight : ndarray (cells,)
        ``det(J Jᵀ)`` (m⁶) and the target's angle from the base's facing side (rad).
    base_ok : ndarray (cells,) of bool
        Whether the base criterion holds at the cell.
    """

    shape: tuple[int, int, int]
    origin: np.ndarray
    cell_size: float
    start: int
    target: int
    next_cell: np.ndarray
    reward: np.ndarray
    ends: np.ndarray
    terminal: np.ndarray
    reasons: tuple[str, ...]
    joints: np.ndarray
    base_positions: np.ndarray
    det_jjt: np.ndarray
    sight: np.ndarray
    base_ok: np.ndarray

    @property
    def cells(self) -> int:
        """Number of cells."""
        return int(np.prod(self.shape))

    def centres(self, cells: np.ndarray | None = None) -> np.ndarray:
        """Centres of ``cells`` (flat indices; all when None), world frame, m (k, 3)."""
        index = np.arange(self.cells) if cells is None else np.asarray(cells)
        return self.origin + self.cell_size * np.column_stack(np.unravel_index(index, self.shape))


def build_environment(
    problem: PathProblem, rules: CellRules, deadline: float = float("inf")
) -> CellEnvironment:
    """The cell environment of a manipulator's reach problem.

    Parameters
    ----------
    problem : PathProblem
        Carries the model; its start is the robot's state, its goal the target's region.
    rules : CellRules
        Grid, constraints and rewards.
    deadline : float
        ``time.monotonic()`` by which the environment must be built.

    Raises
    ------
    ValueError
        If the problem carries no robot model (it is not a manipulator's).
    OutOfTime
        If the deadline passes first.
    TooManyCells
        If the grid would have more than ``rules.max_cells`` cells.
    """
    model, start = problem.model, problem.start
    if model is None:
        raise ValueError("a cell environment is a manipulator's: the problem carries no model")
    q0 = start.configuration
    first = model.forward_kinematics(q0).end_effector
    target_offset = np.rint((problem.goal.position - first) / rules.cell_size).astype(int)
    lower = np.minimum(0, target_offset) - rules.margin
    upper = np.maximum(0, target_offset) + rules.margin
    nx, ny, nz = (int(v) for v in upper - lower + 1)
    shape = (nx, ny, nz)
    if np.prod(shape, dtype=float) > rules.max_cells:
        raise TooManyCells(
            f"the grid would have {' × '.join(map(str, shape))} cells, more than max_cells = "
            f"{rules.max_cells}: use larger cells or a smaller margin"
        )
    origin = first + rules.cell_size * lower
    indices = np.column_stack(np.unravel_index(np.arange(np.prod(shape)), shape))
    centres = origin + rules.cell_size * indices
    start_cell = int(np.ravel_multi_index(tuple(-lower), shape))
    target_cell = int(np.ravel_multi_index(tuple(target_offset - lower), shape))
    states = _cell_states(model, q0, centres, problem.goal.position, rules, deadline)
    terminal = np.array([bool(reason) for reason in states.reasons])
    terminal[start_cell] = False  # where the arm already is
    displacement = np.linalg.norm(centres - first, axis=1)
    base_moved = np.linalg.norm(states.base_positions - start.position, axis=1)
    base_ok = base_moved <= rules.base_ratio * displacement + 1e-12
    next_cell = _transitions(indices, shape)
    ends = terminal.copy()
    ends[target_cell] = True
    entering = np.where(base_ok, rules.step_reward, rules.step_reward + rules.base_penalty)
    entering[terminal] = rules.terminal_reward
    entering[target_cell] = rules.target_reward
    return CellEnvironment(
        shape=shape,
        origin=origin,
        cell_size=rules.cell_size,
        start=start_cell,
        target=target_cell,
        next_cell=next_cell,
        reward=entering[next_cell],
        ends=ends,
        terminal=terminal,
        reasons=tuple("" if not terminal[c] else states.reasons[c] for c in range(len(centres))),
        joints=states.joints,
        base_positions=states.base_positions,
        det_jjt=states.det_jjt,
        sight=states.sight,
        base_ok=base_ok,
    )


class TooManyCells(ValueError):
    """The grid the rules ask for is larger than they allow."""


def _transitions(indices: np.ndarray, shape: tuple[int, int, int]) -> np.ndarray:
    """``next_cell`` (cells, 6): each action's cell, or the same cell at the grid's edge."""
    moved = indices[:, None, :] + ACTIONS[None, :, :]
    inside = np.all((moved >= 0) & (moved < np.array(shape)), axis=2)
    moved = np.where(inside[:, :, None], moved, indices[:, None, :])
    return np.ravel_multi_index(tuple(moved.transpose(2, 0, 1)), shape)


@dataclass(frozen=True)
class _CellStates:
    joints: np.ndarray
    base_positions: np.ndarray
    det_jjt: np.ndarray
    sight: np.ndarray
    reasons: list[str]


def _cell_states(
    model,
    q0: np.ndarray,
    centres: np.ndarray,
    target: np.ndarray,
    rules: CellRules,
    deadline: float,
) -> _CellStates:
    """The arm at every cell centre and the constraint each breaks ("" for none)."""
    side = (
        facing_axis(q0[3:7], target - q0[:3])
        if rules.facing_axis is None
        else np.asarray(rules.facing_axis, dtype=float)
    )
    n = q0.size - 7
    joints = np.full((len(centres), n), np.nan)
    bases = np.tile(q0[:3], (len(centres), 1))
    det = np.zeros(len(centres))
    sight = np.full(len(centres), np.pi)
    reasons = []
    for cell, centre in enumerate(centres):
        check(deadline, f"{cell} of {len(centres)} cells")
        result = model.inverse_kinematics(centre, q0, base="centre-of-mass", tolerance=1e-9)
        if not result.converged:
            reasons.append(f"no inverse kinematics ({result.status})")
            continue
        q = result.q
        joints[cell] = np.angle(np.exp(1j * q[7:]))  # wrapped to (−π, π]
        bases[cell] = q[:3]
        det[cell] = model.det_jjt(q, position_only=True)
        sight[cell] = sight_angle(q[3:7], side, target - q[:3])
        reasons.append(_broken(joints[cell], det[cell], sight[cell], rules))
    return _CellStates(joints, bases, det, sight, reasons)


def _broken(joints: np.ndarray, det: float, sight: float, rules: CellRules) -> str:
    """The first constraint a cell's state breaks, or ""."""
    if np.any(np.abs(joints) > rules.joint_limit):
        return "joint limit"
    if det <= rules.singular_det:
        return "singularity"
    if sight > rules.sight_limit:
        return "target out of sight"
    return ""
