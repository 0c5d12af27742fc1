"""The inertial reference for relative orbital motion, and its agreement with brahe."""

from __future__ import annotations

import numpy as np
import pytest

from dcsim.bench import dynamics
from dcsim.bench import orbit_reference as ref
from dcsim.bench.orbit_peer import BRAHE_CONSTANTS, brahe_missing, propagate_brahe

BRAHE = brahe_missing()
needs_brahe = pytest.mark.skipif(BRAHE is not None, reason=str(BRAHE))

LEO = ref.OrbitElements(
    a=ref.R_EARTH + 400e3, e=0.0, i=np.radians(51.6), raan=0.0, argp=0.0, nu=0.0
)
"""A 400 km circular orbit at the space station's inclination."""
ECCENTRIC = ref.OrbitElements(a=7.5e6, e=0.1, i=np.radians(63.4), raan=1.2, argp=2.1, nu=0.4)


def period(elements: ref.OrbitElements, mu: float = ref.MU_EARTH) -> float:
    """The two-body period, s."""
    return 2 * np.pi * np.sqrt(elements.a**3 / mu)


def energy(position, velocity, model="two-body"):
    """Specific orbital energy (kinetic plus the model's potential), J/kg."""
    r = np.linalg.norm(position, axis=-1)
    potential = -ref.MU_EARTH / r
    if model == "j2":
        sin2_lat = (position[..., 2] / r) ** 2
        potential += (
            ref.MU_EARTH / r * ref.J2_EARTH * (ref.R_EARTH / r) ** 2 * (3 * sin2_lat - 1) / 2
        )
    return 0.5 * np.sum(velocity**2, axis=-1) + potential


def some_deputies(rng, n):
    """Relative positions within ~1 km (m) and velocities of ~1 m/s."""
    return rng.normal(scale=500.0, size=(n, 3)), rng.normal(scale=1.0, size=(n, 3))


@pytest.mark.parametrize("elements", [LEO, ECCENTRIC])
def test_two_body_keeps_energy_and_angular_momentum(elements):
    position, velocity = ref.elements_to_state(elements)
    times = np.linspace(0.0, period(elements), 50)
    positions, velocities = ref.propagate_inertial(position[None], velocity[None], times)
    h = np.cross(positions[:, 0], velocities[:, 0])
    assert np.linalg.norm(h - h[0], axis=-1).max() / np.linalg.norm(h[0]) < 1e-10
    e = energy(positions[:, 0], velocities[:, 0])
    assert np.abs(e / e[0] - 1).max() < 1e-10
    # one period later the body is back where it started
    assert np.linalg.norm(positions[-1, 0] - position) < 1e-3


def test_j2_keeps_its_energy_and_polar_angular_momentum_but_turns_the_plane():
    position, velocity = ref.elements_to_state(ECCENTRIC)
    times = np.linspace(0.0, period(ECCENTRIC), 50)
    positions, velocities = ref.propagate_inertial(position[None], velocity[None], times, "j2")
    e = energy(positions[:, 0], velocities[:, 0], "j2")
    assert np.abs(e / e[0] - 1).max() < 1e-10
    h = np.cross(positions[:, 0], velocities[:, 0])
    assert np.abs(h[:, 2] / h[0, 2] - 1).max() < 1e-10
    turn = np.arccos(h[-1] @ h[0] / np.linalg.norm(h[-1]) / np.linalg.norm(h[0]))
    assert turn > 1e-4  # the node regresses by ~0.3° an orbit at this inclination


def test_elements_to_state_and_back():
    position, velocity = ref.elements_to_state(ECCENTRIC)
    back = ref.state_to_elements(position, velocity)
    assert np.array([back.a, back.e, back.i, back.raan, back.argp, back.nu]) == pytest.approx(
        [ECCENTRIC.a, ECCENTRIC.e, ECCENTRIC.i, ECCENTRIC.raan, ECCENTRIC.argp, ECCENTRIC.nu],
        rel=1e-12,
    )
    r, v = np.linalg.norm(position), np.linalg.norm(velocity)
    assert v**2 == pytest.approx(ref.MU_EARTH * (2 / r - 1 / ECCENTRIC.a), rel=1e-13)
    at_perigee = ref.elements_to_state(ref.OrbitElements(**{**vars(ECCENTRIC), "nu": 0.0}))[0]
    assert np.linalg.norm(at_perigee) == pytest.approx(ECCENTRIC.a * (1 - ECCENTRIC.e), rel=1e-14)


def test_elements_of_a_circular_or_equatorial_orbit_are_refused():
    for elements in (LEO, ref.OrbitElements(7e6, 0.1, 0.0, 0.0, 0.0, 0.0)):
        with pytest.raises(ValueError, match="eccentric, inclined"):
            ref.state_to_elements(*ref.elements_to_state(elements))


@pytest.mark.parametrize("model", ref.ORBIT_MODELS)
def test_relative_states_map_to_inertial_and_back(model):
    rng = np.random.default_rng(3)
    positions, velocities = ref.propagate_inertial(
        *[part[None] for part in ref.elements_to_state(ECCENTRIC)], np.linspace(0, 3000, 7), model
    )
    frame = ref.LvlhFrame.of_chief(
        positions[:, 0], velocities[:, 0], ref.gravity(positions[:, 0], model)
    )
    rho, rhodot = some_deputies(rng, 7 * 20)
    rho, rhodot = rho.reshape(7, 20, 3), rhodot.reshape(7, 20, 3)
    back = frame.from_inertial(*frame.to_inertial(rho, rhodot))
    assert np.abs(back[0] - rho).max() < 1e-9
    assert np.abs(back[1] - rhodot).max() < 1e-9


def test_the_frame_is_right_handed_radial_along_track_normal():
    position, velocity = ref.elements_to_state(ECCENTRIC)
    frame = ref.LvlhFrame.of_chief(position, velocity, ref.gravity(position))
    c = frame.rotation
    assert c.T @ c == pytest.approx(np.eye(3), abs=1e-15)
    assert np.linalg.det(c) == pytest.approx(1.0)
    assert c.T @ position == pytest.approx([np.linalg.norm(position), 0, 0], abs=1e-8)
    assert (c.T @ velocity)[1] > 0 and (c.T @ velocity)[2] == pytest.approx(0, abs=1e-9)


@pytest.mark.parametrize("model", ref.ORBIT_MODELS)
def test_the_frame_rate_and_the_relative_velocity_are_time_derivatives(model):
    """ω is what the frame's rotation does (Cᵀ dC/dt = [ω]×) and ρ̇ is dρ/dt: central
    differences of the propagated frame and relative positions, 0.5 s apart."""
    rng = np.random.default_rng(5)
    times = np.array([0.0, 0.5, 1.0, 1500.0, 1500.5, 1501.0])
    trajectory = ref.propagate_relative(ECCENTRIC, *some_deputies(rng, 4), times, model)
    for middle in (1, 4):
        c = trajectory.frame.rotation
        skew = c[middle].T @ (c[middle + 1] - c[middle - 1]) / 1.0
        rate = np.array([skew[2, 1], skew[0, 2], skew[1, 0]])
        assert rate == pytest.approx(trajectory.frame.rate[middle], rel=1e-6, abs=1e-12)
        derivative = (trajectory.rho[middle + 1] - trajectory.rho[middle - 1]) / 1.0
        assert np.abs(derivative - trajectory.rhodot[middle]).max() < 1e-6
    omega_x = trajectory.frame.rate[:, 0]
    if model == "two-body":
        assert np.abs(omega_x).max() < 1e-15
    else:  # the orbit plane turns under J2, ~J2 n (R/r)² sin 2i
        assert np.abs(omega_x).min() > 1e-7


def radial_offset_at_rest(model):
    """10 m radial, at rest in LVLH, on the 400 km orbit, sampled every 10 s for 1800 s."""
    times = np.linspace(0.0, 1800.0, 181)
    return times, ref.propagate_relative(LEO, [[10.0, 0.0, 0.0]], np.zeros((1, 3)), times, model)


def test_a_radial_offset_follows_clohessy_wiltshire_under_two_body():
    """Measured 4.2e-4 m largest difference (the nonlinear terms, ~ρ²/r per radian), with
    ~70 m of along-track drift."""
    times, exact = radial_offset_at_rest("two-body")
    rho, rhodot = ref.cw_relative(LEO.a, [[10.0, 0.0, 0.0]], np.zeros((1, 3)), times)
    assert rho[-1, 0] == pytest.approx([53.47, -68.58, 0.0], abs=0.01)
    difference = np.linalg.norm(exact.rho - rho, axis=-1).max()
    assert 2e-4 < difference < 6e-4
    assert np.linalg.norm(exact.rhodot - rhodot, axis=-1).max() < 1e-6


def test_j2_moves_the_radial_offset_by_a_fifth_of_a_metre():
    """Measured 0.182 m after 1800 s, the largest difference from two-body."""
    _, two_body = radial_offset_at_rest("two-body")
    _, j2 = radial_offset_at_rest("j2")
    moved = np.linalg.norm(j2.rho - two_body.rho, axis=-1)
    assert moved.max() == pytest.approx(0.182, abs=0.01)


def test_cw_transition_composes_and_starts_at_identity():
    n = np.sqrt(ref.MU_EARTH / LEO.a**3)
    phi = ref.cw_transition(n, np.array([0.0, 700.0, 1300.0, 2000.0]))
    assert phi[0] == pytest.approx(np.eye(6))
    assert phi[1] @ phi[2] == pytest.approx(phi[3], rel=1e-12, abs=1e-9)


def test_the_frame_turns_faster_at_perigee():
    """ω_z = |h|/r² over an e = 0.01 orbit: its extremes at perigee and apogee are in the
    ratio ((1 + e)/(1 − e))²."""
    e = 0.01
    elements = ref.OrbitElements(LEO.a, e, LEO.i, 0.3, 0.7, 0.0)
    times = np.linspace(0.0, period(elements), 201)
    trajectory = ref.propagate_relative(elements, np.zeros((1, 3)), np.zeros((1, 3)), times)
    omega_z = trajectory.frame.rate[:, 2]
    assert omega_z.max() / omega_z.min() == pytest.approx(((1 + e) / (1 - e)) ** 2, rel=1e-9)
    assert np.argmax(omega_z) == 0 and np.argmin(omega_z) == 100


def test_unknown_models_and_bad_times_are_refused():
    position, velocity = ref.elements_to_state(LEO)
    with pytest.raises(ValueError, match="unknown orbit model 'j3'; use one of two-body, j2"):
        ref.propagate_inertial(position[None], velocity[None], [0.0, 1.0], "j3")
    with pytest.raises(ValueError, match="non-decreasing"):
        ref.propagate_inertial(position[None], velocity[None], [1.0, 0.0, 2.0])
    with pytest.raises(ValueError, match="ending after 0 s"):
        ref.propagate_inertial(position[None], velocity[None], [0.0])


@needs_brahe
def test_brahe_constants_are_brahes_own():
    import brahe

    assert BRAHE_CONSTANTS == {
        "mu": brahe.GM_EARTH,
        "radius": brahe.R_EARTH,
        "j2": brahe.J2_EARTH,
    }
    position = np.array([4e6, 3e6, 4.5e6])
    assert brahe.accel_earth_zonal_gravity(position, 2) == pytest.approx(
        ref.gravity(position, "j2", **BRAHE_CONSTANTS), rel=1e-14
    )


def fly_with_brahe(elements, rho0, rhodot0, duration, model):
    """A chief at ``elements`` and one deputy at ``rho0`` (m), ``rhodot0`` (m/s) in its
    LVLH frame, mapped to ECI with brahe's constants and flown for ``duration`` s by the
    reference (DOP853, rtol 1e-12) and by brahe (RKN12(10), tolerance 1e-12).

    Returns the reference's and brahe's ends, each ECI positions (m) and velocities (m/s)
    of chief and deputy, (2, 3) each.
    """
    chief = ref.elements_to_state(elements, BRAHE_CONSTANTS["mu"])
    frame = ref.LvlhFrame.of_chief(*chief, ref.gravity(chief[0], model, **BRAHE_CONSTANTS))
    deputy = frame.to_inertial(np.asarray(rho0, float)[None], np.asarray(rhodot0, float)[None])
    position, velocity = np.vstack([chief[0], deputy[0]]), np.vstack([chief[1], deputy[1]])
    ours = ref.propagate_inertial(position, velocity, [0.0, duration], model, **BRAHE_CONSTANTS)
    return (ours[0][-1], ours[1][-1]), propagate_brahe(position, velocity, duration, model)


def deputy_in_lvlh(position, velocity, model):
    """The deputy's position (m) in the chief's LVLH frame, by the reference's map, from
    chief's and deputy's ECI positions (m) and velocities (m/s), (2, 3) each."""
    gravity = ref.gravity(position[0], model, **BRAHE_CONSTANTS)
    frame = ref.LvlhFrame.of_chief(position[0], velocity[0], gravity)
    return frame.from_inertial(position[1:], velocity[1:])[0][0]


@needs_brahe
@pytest.mark.parametrize("model", ref.ORBIT_MODELS)
def test_brahe_ends_one_orbit_where_the_reference_does(model):
    """Chief on the 400 km orbit and a deputy 10 m radial at rest, one orbit, each in
    brahe (RKN12(10), tolerance 1e-12) and in the reference (DOP853, rtol 1e-12).

    Measured: 1.25e-5 m apart in ECI for both models, which is the reference's own
    integration error (tightening it to rtol 1e-13 moves its end by 1.1e-5 m), 1.4e-8 m/s
    in velocity, and 1.2e-7 m apart in the deputy's LVLH position. Under J2 the chief ends
    kilometres from its two-body end, so the J2 agreement is not two-body's."""
    duration = period(LEO, BRAHE_CONSTANTS["mu"])
    ours, theirs = fly_with_brahe(LEO, [10.0, 0.0, 0.0], np.zeros(3), duration, model)
    assert np.linalg.norm(ours[0] - theirs[0], axis=-1).max() < 1e-4
    assert np.linalg.norm(ours[1] - theirs[1], axis=-1).max() < 1e-7
    relative = deputy_in_lvlh(*ours, model) - deputy_in_lvlh(*theirs, model)
    assert np.linalg.norm(relative) < 1e-6
    if model == "j2":
        two_body = fly_with_brahe(LEO, [10.0, 0.0, 0.0], np.zeros(3), duration, "two-body")[1]
        assert np.linalg.norm(two_body[0] - theirs[0], axis=-1).min() > 1e3


BENCH_CASES = dynamics.drift_cases(
    ("two-body", "j2"), (0.0, 0.01), (100.0, 1000.0, 10000.0), dynamics.AXES
)
"""The exact models' cases of ``dcsim bench dynamics`` (its default grid)."""


@needs_brahe
@pytest.mark.parametrize(
    "case",
    BENCH_CASES,
    ids=[f"{c.model}-e{c.eccentricity:g}-{c.separation:g}m-{c.axis}" for c in BENCH_CASES],
)
def test_brahe_agrees_with_the_reference_on_the_bench_cases(case):
    """Each drift case of ``dcsim bench dynamics`` under two-body and J2: the bench's
    chief elements, the robot's start and drift-free velocity, one orbit rounded to the
    0.1 s control period; flown by brahe and by the reference with brahe's constants.
    ``-s`` prints each case's figures.

    Measured, worst over the 36 cases: chief and deputy 1.66e-5 m apart in ECI (1.26e-5 m
    on the circular orbit), the deputy's LVLH position 6.3e-7 m apart (10 km radial,
    e = 0.01). Both are the reference's integration error at rtol 1e-12: at rtol 1e-13
    the ECI ends agree to 1.4e-6 m and the LVLH positions to 1.7e-7 m, while brahe's
    own ends move by at most 1.1e-7 m in LVLH from tolerance 1e-12 to 1e-14. The
    bounds are ten times the measured worst."""
    orbit = dynamics.drift_scenario(case, 1.0).world.orbit
    velocity = dynamics.drift_free_velocity(orbit, case.start)
    duration = dynamics.drift_duration(orbit, 1.0, 0.1)
    model = case.reference_model
    ours, theirs = fly_with_brahe(
        dynamics.chief_elements(orbit), case.start, velocity, duration, model
    )
    apart = np.linalg.norm(ours[0] - theirs[0], axis=-1)
    relative = np.linalg.norm(deputy_in_lvlh(*ours, model) - deputy_in_lvlh(*theirs, model))
    print(
        f"{case.model}, e = {case.eccentricity:g}, {case.separation:g} m on {case.axis}: "
        f"chief {apart[0]:.3g} m, deputy {apart[1]:.3g} m apart in ECI, "
        f"{relative:.3g} m in LVLH"
    )
    assert apart.max() < 1.7e-4
    assert relative < 6.3e-6
