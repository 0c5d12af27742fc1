"""The torque-free tumble of a rigid target against references built independently here:
the closed-form motion of an axisymmetric body, and scipy's DOP853 on Euler's equations
with rotation-matrix kinematics for a triaxial one (near its intermediate axis too)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from dcsim.torque_free import TorqueFreeRotation

DURATION = 60.0  # s
SAMPLE = 0.5  # s between comparisons
CALLS = [0.0005, 0.01]  # s: one physics step, one control period
ATTITUDE_TOLERANCE = 1e-6  # rad
RATE_TOLERANCE = 1e-9  # rad/s
CONSERVATION_TOLERANCE = 1e-10  # relative

RATE = math.radians(5.0)  # rad/s
OBLIQUE = np.array([1.0, -2.0, 3.0]) / math.sqrt(14.0)
"""Direction of the initial angular velocity, world frame."""
ATTITUDE0 = Rotation.from_euler("zyx", [30.0, -20.0, 75.0], degrees=True)
"""Initial body-to-world attitude."""


def cylinder(mass, radius, length):
    """Principal moments (I1 = I2, I3 about the axis) of a solid cylinder, kg m^2."""
    axial = 0.5 * mass * radius**2
    transverse = mass * (3.0 * radius**2 + length**2) / 12.0
    return transverse, axial


AXISYMMETRIC = {
    "upper stage": cylinder(1200.0, 1.2, 4.0),  # I3 < I1 (prolate)
    "flat disc": cylinder(500.0, 1.5, 0.3),  # I3 > I1 (oblate)
}


def box_moments(mass, a, b, c):
    """Principal moments of a solid box of sides a, b, c (m), kg m^2."""
    return np.array([b * b + c * c, a * a + c * c, a * a + b * b]) * mass / 12.0


PRINCIPAL = Rotation.from_euler("xyz", [20.0, -35.0, 50.0], degrees=True).as_matrix()
"""Principal axes (columns) in the body frame of the triaxial body."""
MOMENTS = box_moments(1500.0, 1.0, 2.0, 3.0)  # 1625, 1250, 625 kg m^2
TRIAXIAL_INERTIA = PRINCIPAL @ np.diag(MOMENTS) @ PRINCIPAL.T
"""A full (non-diagonal) tensor: the box's inertia in a body frame turned from its axes."""
MIDDLE_AXIS = PRINCIPAL[:, 1]  # body frame
NEAR_MIDDLE = PRINCIPAL @ (np.array([0.05, 1.0, 0.05]) * math.radians(30.0))
"""Body rates 30 deg/s about the intermediate axis, 5 % off it: it flips over at about
14 s and back at about 50 s."""


def world_rate(body_rates):
    """Body-frame rates at the initial attitude in the world frame, rad/s."""
    return ATTITUDE0.apply(body_rates)


TRIAXIAL_CASES = {
    "oblique": RATE * OBLIQUE,
    "near intermediate axis": world_rate(NEAR_MIDDLE),
}


def axisymmetric_motion(transverse, axial, attitude0, rate0):
    """Closed-form torque-free motion of an axisymmetric rigid body.

    Body frame = principal axes, ``I = diag(I1, I1, I3)``, symmetry axis ``e3``; in the
    world ``b3(t) = R(t) e3``. Euler's equations give ``I1 ω̇1 = (I1 - I3) ω3 ω2``,
    ``I1 ω̇2 = -(I1 - I3) ω3 ω1``, ``I3 ω̇3 = 0``: ``ω3`` is constant and the
    transverse rates turn about ``e3`` at ``-W_r``, ``W_r = ω3 (I1 - I3) / I1``. The
    angular momentum ``H = R I ω_b = I1 ω + (I3 - I1) ω3 b3`` is constant in the world,
    so ``ω = H / I1 - (I3 - I1) ω3 / I1 b3 = W_p h + W_r b3`` with ``h = H / |H|`` and
    ``W_p = |H| / I1``. The attitude ``R(t) = Rot(h, W_p t) R0 Rot(e3, W_r t)`` has
    ``Ṙ Rᵀ = [W_p h]× + Rot(h, W_p t) R0 [W_r e3]× R0ᵀ Rot(h, W_p t)ᵀ
    = [W_p h + W_r b3]×``, i.e. exactly that angular velocity, and starts at ``R0``:
    it is the motion. ``b3`` precesses about ``h`` at ``W_p`` at a constant angle.

    Returns
    -------
    callable
        ``t -> (Rotation, ω world rad/s)``.
    """
    inertia = np.diag([transverse, transverse, axial])
    body0 = attitude0.inv().apply(rate0)
    momentum = attitude0.apply(inertia @ body0)
    h = momentum / np.linalg.norm(momentum)
    precession = np.linalg.norm(momentum) / transverse
    spin = body0[2] * (transverse - axial) / transverse

    def at(t):
        rotation = (
            Rotation.from_rotvec(h * precession * t)
            * attitude0
            * Rotation.from_rotvec([0.0, 0.0, spin * t])
        )
        return rotation, precession * h + spin * rotation.apply([0.0, 0.0, 1.0])

    return at


def error_angle(reference, attitude):
    """Angle between a reference attitude and a quaternion [x, y, z, w], rad."""
    return (reference.inv() * Rotation.from_quat(attitude)).magnitude()


def sample_times():
    return np.arange(1, round(DURATION / SAMPLE) + 1) * SAMPLE


def propagate(rotation, call):
    """Advance ``rotation`` in calls of ``call`` s, yielding it at every sample time."""
    calls = round(SAMPLE / call)
    for t in sample_times():
        for _ in range(calls):
            rotation.advance(call)
        yield t, rotation


@pytest.mark.parametrize("name", AXISYMMETRIC)
def test_closed_form_is_torque_free_motion(name):
    """The reference's own consistency: starts at the initial state, keeps H, and its
    angular velocity is the one its attitude turns at (central differences)."""
    transverse, axial = AXISYMMETRIC[name]
    inertia = np.diag([transverse, transverse, axial])
    rate0 = RATE * OBLIQUE
    motion = axisymmetric_motion(transverse, axial, ATTITUDE0, rate0)
    rotation, rate = motion(0.0)
    assert error_angle(rotation, ATTITUDE0.as_quat()) < 1e-15
    np.testing.assert_allclose(rate, rate0, rtol=0, atol=1e-16)
    momentum0 = ATTITUDE0.apply(inertia @ ATTITUDE0.inv().apply(rate0))
    delta = 1e-3
    for t in np.linspace(0.0, DURATION, 13):
        rotation, rate = motion(t)
        matrix = rotation.as_matrix()
        momentum = matrix @ inertia @ matrix.T @ rate
        np.testing.assert_allclose(
            momentum, momentum0, rtol=0, atol=1e-12 * np.linalg.norm(momentum0)
        )
        turned = motion(t + delta)[0] * motion(t - delta)[0].inv()
        np.testing.assert_allclose(turned.as_rotvec() / (2 * delta), rate, rtol=0, atol=1e-10)


@pytest.mark.parametrize("call", CALLS)
@pytest.mark.parametrize("name", AXISYMMETRIC)
def test_axisymmetric_body_follows_the_closed_form(name, call):
    transverse, axial = AXISYMMETRIC[name]
    rate0 = RATE * OBLIQUE
    motion = axisymmetric_motion(transverse, axial, ATTITUDE0, rate0)
    rotation = TorqueFreeRotation(
        np.diag([transverse, transverse, axial]), ATTITUDE0.as_quat(), rate0
    )
    worst_angle = worst_rate = 0.0
    for t, state in propagate(rotation, call):
        reference, reference_rate = motion(t)
        worst_angle = max(worst_angle, error_angle(reference, state.attitude))
        worst_rate = max(
            worst_rate, np.max(np.abs(np.subtract(state.angular_velocity, reference_rate)))
        )
    print(f"{name}, {call} s calls: attitude {worst_angle:.1e} rad, rate {worst_rate:.1e} rad/s")
    assert rotation.time == pytest.approx(DURATION, abs=1e-9)
    assert worst_angle <= ATTITUDE_TOLERANCE
    assert worst_rate <= RATE_TOLERANCE


@pytest.mark.parametrize("name", AXISYMMETRIC)
def test_axisymmetric_nutation_angle_is_constant(name):
    """The angle between the symmetry axis b3 and the (initial, world) angular momentum."""
    transverse, axial = AXISYMMETRIC[name]
    inertia = np.diag([transverse, transverse, axial])
    rate0 = RATE * OBLIQUE
    momentum = ATTITUDE0.apply(inertia @ ATTITUDE0.inv().apply(rate0))

    def nutation(attitude):
        b3 = Rotation.from_quat(attitude).apply([0.0, 0.0, 1.0])
        return math.atan2(np.linalg.norm(np.cross(b3, momentum)), b3 @ momentum)

    rotation = TorqueFreeRotation(inertia, ATTITUDE0.as_quat(), rate0)
    angle0 = nutation(rotation.attitude)
    assert 0.1 < angle0 < math.pi / 2 - 0.1  # a real nutation, not a flat spin
    changes = [abs(nutation(state.attitude) - angle0) for _, state in propagate(rotation, 0.01)]
    print(f"{name}: nutation {angle0:.3f} rad, largest change {max(changes):.1e} rad")
    assert max(changes) <= 1e-9


def dop853_reference(inertia, attitude0, rate0):
    """Euler's equations and rotation-matrix kinematics ``Ṙ = R [ω_b]×`` by DOP853.

    Returns
    -------
    (times, list of Rotation, ndarray (N, 3) world angular velocities)
    """

    def derivative(_, y):
        matrix, body = y[:9].reshape(3, 3), y[9:]
        skew = np.array(
            [[0.0, -body[2], body[1]], [body[2], 0.0, -body[0]], [-body[1], body[0], 0.0]]
        )
        body_rate = np.linalg.solve(inertia, -np.cross(body, inertia @ body))
        return np.concatenate(((matrix @ skew).ravel(), body_rate))

    matrix0 = attitude0.as_matrix()
    y0 = np.concatenate((matrix0.ravel(), matrix0.T @ rate0))
    times = sample_times()
    solution = solve_ivp(
        derivative, (0.0, DURATION), y0, method="DOP853", t_eval=times, rtol=1e-12, atol=1e-14
    )
    assert solution.success
    matrices = solution.y[:9].T.reshape(-1, 3, 3)
    rates = np.einsum("nij,jn->ni", matrices, solution.y[9:])
    return times, [Rotation.from_matrix(m) for m in matrices], rates


@pytest.mark.parametrize("call", CALLS)
@pytest.mark.parametrize("case", TRIAXIAL_CASES)
def test_triaxial_body_follows_dop853(case, call):
    rate0 = TRIAXIAL_CASES[case]
    _, references, reference_rates = dop853_reference(TRIAXIAL_INERTIA, ATTITUDE0, rate0)
    rotation = TorqueFreeRotation(TRIAXIAL_INERTIA, ATTITUDE0.as_quat(), rate0)
    angles, rate_errors, norm_errors = [], [], []
    for k, (_, state) in enumerate(propagate(rotation, call)):
        angles.append(error_angle(references[k], state.attitude))
        rate_errors.append(np.max(np.abs(np.subtract(state.angular_velocity, reference_rates[k]))))
        norm_errors.append(abs(math.hypot(*state.attitude) - 1.0))
    print(
        f"{case}, {call} s calls: attitude {max(angles):.1e} rad, rate {max(rate_errors):.1e} rad/s"
    )
    assert max(angles) <= ATTITUDE_TOLERANCE
    assert max(rate_errors) <= RATE_TOLERANCE
    assert max(norm_errors) <= 1e-15  # renormalised each sub-step: a unit quaternion to rounding


def test_near_intermediate_axis_the_body_flips():
    """The hard case is hard: the rate about the middle axis changes sign in 60 s."""
    rotation = TorqueFreeRotation(
        TRIAXIAL_INERTIA, ATTITUDE0.as_quat(), TRIAXIAL_CASES["near intermediate axis"]
    )
    about_middle = [np.dot(state.body_rates, MIDDLE_AXIS) for _, state in propagate(rotation, 0.01)]
    flips = np.count_nonzero(np.diff(np.sign(about_middle)))
    assert flips >= 2


@pytest.mark.parametrize("case", TRIAXIAL_CASES)
def test_triaxial_momentum_and_energy_are_conserved(case):
    rate0 = TRIAXIAL_CASES[case]
    body0 = ATTITUDE0.inv().apply(rate0)
    momentum0 = ATTITUDE0.apply(TRIAXIAL_INERTIA @ body0)
    energy0 = 0.5 * body0 @ TRIAXIAL_INERTIA @ body0
    rotation = TorqueFreeRotation(TRIAXIAL_INERTIA, ATTITUDE0.as_quat(), rate0)
    np.testing.assert_allclose(
        rotation.angular_momentum, momentum0, rtol=0, atol=1e-15 * np.linalg.norm(momentum0)
    )
    assert rotation.kinetic_energy == pytest.approx(energy0, rel=1e-15)
    momentum_drift = energy_drift = 0.0
    for _, state in propagate(rotation, 0.01):
        momentum_drift = max(
            momentum_drift, np.linalg.norm(np.subtract(state.angular_momentum, momentum0))
        )
        energy_drift = max(energy_drift, abs(state.kinetic_energy - energy0))
    momentum_drift /= np.linalg.norm(momentum0)
    energy_drift /= energy0
    print(f"{case}: relative drift of momentum {momentum_drift:.1e}, of energy {energy_drift:.1e}")
    assert momentum_drift <= CONSERVATION_TOLERANCE
    assert energy_drift <= CONSERVATION_TOLERANCE


def test_properties_agree_with_the_state():
    """Body rates, world rates, momentum and energy read back from a state set twice."""
    rotation = TorqueFreeRotation(TRIAXIAL_INERTIA, [0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0])
    rotation.advance(1.0)
    attitude = Rotation.from_euler("xyz", [-40.0, 10.0, 120.0], degrees=True)
    rate = np.array([0.03, -0.02, 0.05])
    rotation.set_state(attitude.as_quat(), rate)
    body = attitude.inv().apply(rate)
    assert rotation.time == 1.0
    assert error_angle(attitude, rotation.attitude) < 1e-15
    np.testing.assert_allclose(rotation.angular_velocity, rate, rtol=0, atol=1e-16)
    np.testing.assert_allclose(rotation.body_rates, body, rtol=0, atol=1e-16)
    np.testing.assert_allclose(
        rotation.angular_momentum, attitude.apply(TRIAXIAL_INERTIA @ body), rtol=1e-14
    )
    assert rotation.kinetic_energy == pytest.approx(0.5 * body @ TRIAXIAL_INERTIA @ body, rel=1e-14)


def test_long_durations_are_split_into_sub_steps_of_at_most_max_step():
    """One call of 1 s is the same, to the bit, as 100 calls of 0.01 s (the default
    ``max_step``); with ``max_step`` 3 ms it is 334 calls of 1/334 s, the fewest equal
    sub-steps no longer than that."""
    rate0 = TRIAXIAL_CASES["near intermediate axis"]
    at_once = TorqueFreeRotation(TRIAXIAL_INERTIA, ATTITUDE0.as_quat(), rate0)
    at_once.advance(1.0)
    stepped = TorqueFreeRotation(TRIAXIAL_INERTIA, ATTITUDE0.as_quat(), rate0)
    for _ in range(100):
        stepped.advance(0.01)
    assert at_once.attitude == stepped.attitude
    assert at_once.body_rates == stepped.body_rates
    finer = TorqueFreeRotation(TRIAXIAL_INERTIA, ATTITUDE0.as_quat(), rate0, max_step=0.003)
    finer.advance(1.0)
    finer_stepped = TorqueFreeRotation(TRIAXIAL_INERTIA, ATTITUDE0.as_quat(), rate0)
    for _ in range(334):
        finer_stepped.advance(1.0 / 334)
    assert finer.attitude == finer_stepped.attitude
    assert finer.body_rates == finer_stepped.body_rates


def test_a_non_unit_quaternion_is_normalised():
    rotation = TorqueFreeRotation(np.eye(3), [0.0, 0.0, 3.0, 4.0], [0.0, 0.0, 0.0])
    assert rotation.attitude == (0.0, 0.0, 0.6, 0.8)
    rotation.set_state([2.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    assert rotation.attitude == (1.0, 0.0, 0.0, 0.0)


BAD_INERTIA = {
    "not symmetric": ([[10.0, 1.0, 0.0], [0.0, 10.0, 0.0], [0.0, 0.0, 10.0]], "not symmetric"),
    "not positive definite": (
        [[10.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 10.0]],
        "not positive definite",
    ),
    "singular": (np.diag([0.0, 5.0, 5.0]), "not positive definite"),
    "triangle inequality": (np.diag([1.0, 2.0, 4.0]), "violates the triangle inequality"),
    "not 3x3": (np.eye(2), "finite 3x3 tensor"),
    "not finite": (np.diag([1.0, 1.0, np.nan]), "finite 3x3 tensor"),
}


@pytest.mark.parametrize("case", BAD_INERTIA)
def test_bad_inertia_is_refused(case):
    inertia, message = BAD_INERTIA[case]
    with pytest.raises(ValueError, match=message):
        TorqueFreeRotation(inertia, [0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.1])


def test_a_thin_rod_meets_the_triangle_inequality_with_equality():
    rotation = TorqueFreeRotation(
        np.diag([1e-3, 2.0, 2.0 + 1e-3]), [0.0, 0.0, 0.0, 1.0], [0.0, 0.1, 0.0]
    )
    assert rotation.kinetic_energy == pytest.approx(0.01)


def test_the_messages_say_what_is_wrong():
    with pytest.raises(ValueError) as excinfo:
        TorqueFreeRotation(np.diag([1.0, 2.0, 4.0]), [0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.1])
    assert str(excinfo.value) == (
        "inertia tensor violates the triangle inequality: the largest principal moment 4 kg m^2 "
        "exceeds the sum of the other two 1 + 2; no rigid body has such moments"
    )
    with pytest.raises(ValueError) as excinfo:
        TorqueFreeRotation(np.eye(3), [0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.1])
    assert str(excinfo.value) == (
        "attitude quaternion has zero length: give a unit quaternion [x, y, z, w], "
        "e.g. [0, 0, 0, 1] for the identity"
    )


BAD_STATES = {
    "zero quaternion": ([0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.1], "zero length"),
    "three-element quaternion": (
        [0.0, 0.0, 1.0],
        [0.0, 0.0, 0.1],
        r"quaternion \[x, y, z, w\], got 3",
    ),
    "infinite quaternion": ([0.0, 0.0, math.inf, 1.0], [0.0, 0.0, 0.1], "must be finite"),
    "two-element rate": ([0.0, 0.0, 0.0, 1.0], [0.0, 0.1], "angular_velocity must have 3"),
    "infinite rate": (
        [0.0, 0.0, 0.0, 1.0],
        [0.0, math.nan, 0.1],
        "angular_velocity must be finite",
    ),
}


@pytest.mark.parametrize("case", BAD_STATES)
def test_bad_states_are_refused_at_construction_and_restart(case):
    attitude, rate, message = BAD_STATES[case]
    with pytest.raises(ValueError, match=message):
        TorqueFreeRotation(np.eye(3), attitude, rate)
    rotation = TorqueFreeRotation(np.eye(3), [0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.1])
    with pytest.raises(ValueError, match=message):
        rotation.set_state(attitude, rate)
    assert rotation.attitude == (0.0, 0.0, 0.0, 1.0)  # a refused state leaves it as it was


@pytest.mark.parametrize("duration", [-1e-3, math.nan, math.inf])
def test_bad_durations_are_refused(duration):
    rotation = TorqueFreeRotation(np.eye(3), [0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.1])
    with pytest.raises(ValueError, match="duration must be a finite time >= 0 s"):
        rotation.advance(duration)
    assert rotation.time == 0.0


@pytest.mark.parametrize("max_step", [0.0, -0.01, math.nan])
def test_bad_max_step_is_refused(max_step):
    with pytest.raises(ValueError, match="max_step must be a positive number of seconds"):
        TorqueFreeRotation(np.eye(3), [0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.1], max_step=max_step)


def test_zero_duration_changes_nothing():
    rotation = TorqueFreeRotation(TRIAXIAL_INERTIA, ATTITUDE0.as_quat(), [0.1, 0.0, 0.0])
    before = (rotation.attitude, rotation.body_rates)
    rotation.advance(0.0)
    assert (rotation.attitude, rotation.body_rates) == before
    assert rotation.time == 0.0
