"""``dcsim bench peers``: the same slew in dcsim and in Basilisk (when installed)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from dcsim_plugins.controllers.pd import design_gains

from dcsim.bench import peers
from dcsim.bench.basilisk_loop import basilisk_missing, mrp_from_quaternion, quaternion_from_mrp
from dcsim.geometry import rotate
from dcsim.registry.discovery import PluginRegistry

BASILISK = basilisk_missing()
needs_basilisk = pytest.mark.skipif(BASILISK is not None, reason=str(BASILISK))

SHORT = replace(peers.SlewCase(), duration=40.0)
"""The benchmark's slew, cut to 40 s: long enough to converge."""


@pytest.fixture(scope="module")
def registry():
    return PluginRegistry.discover()


@pytest.fixture(scope="module")
def dcsim_rows(registry):
    """dcsim's two rows over the short span: attitude only, and with the position held."""
    return {hold: peers.fly_dcsim(SHORT, hold, registry) for hold in (False, True)}


@pytest.fixture(scope="module")
def basilisk_rows():
    inertia = peers.flyer_inertia(SHORT)
    return {
        hold: peers.fly_peer(peers.basilisk_setup(SHORT, hold, inertia, SHORT.physics_step))
        for hold in (False, True)
    }


@pytest.fixture(scope="module")
def dcsim_wheels(registry):
    """dcsim's slew on the case's four reaction wheels over the short span."""
    return peers.fly_dcsim(SHORT, False, registry, "wheels")


@pytest.fixture(scope="module")
def basilisk_wheels():
    inertia = peers.flyer_inertia(SHORT)
    return peers.fly_peer(peers.basilisk_setup(SHORT, False, inertia, SHORT.physics_step, "wheels"))


@pytest.fixture(scope="module")
def thruster_rows(registry):
    """Each side's slew on the case's twelve thrusters over the short span (Basilisk's
    None when it is not installed)."""
    ours = peers.fly_dcsim(SHORT, False, registry, "thrusters")
    if BASILISK is not None:
        return ours, None
    inertia = peers.flyer_inertia(SHORT)
    setup = peers.basilisk_setup(SHORT, False, inertia, SHORT.physics_step, "thrusters")
    return ours, peers.fly_peer(setup)


def wheel_momentum_in_world(flight: peers.Flight, index: int) -> np.ndarray:
    """The wheels' angular momentum ``R A h`` at sample ``index``, world frame, N·m·s."""
    body = np.array(SHORT.wheel_axes).T @ (SHORT.wheel_inertia * flight.wheel_speed[index])
    error = flight.pointing_error[index]
    assert error < 1e-6  # at the goal attitude: R is the goal's
    return rotate(np.asarray(SHORT.goal_attitude), body)


def test_the_case_is_a_real_slew_and_its_gains_are_the_pd_plugins():
    assert np.degrees(
        peers.pointing_errors(np.array([SHORT.initial_attitude]), SHORT.goal_attitude)
    ) == pytest.approx(90.0)
    assert SHORT.attitude_gains == pytest.approx(design_gains(0.5, 0.9))
    assert SHORT.position_gains == pytest.approx(design_gains(0.2, 0.9))
    kp, kd = SHORT.attitude_gains
    assert SHORT.mrp_gains(40.0) == pytest.approx((4 * 40.0 * kp, 40.0 * kd))


def test_the_free_flyer_is_a_sphere_of_the_cases_mass():
    inertia = peers.flyer_inertia(SHORT)
    assert inertia == pytest.approx(0.4 * SHORT.mass * SHORT.radius**2 * np.eye(3))
    with pytest.raises(ValueError, match="only for an isotropic inertia"):
        peers.basilisk_setup(SHORT, False, np.diag([40.0, 40.0, 50.0]), 0.01)


def test_dcsim_slews_to_the_goal_without_saturating(dcsim_rows):
    for flight in dcsim_rows.values():
        assert flight.times[-1] == pytest.approx(SHORT.duration)
        assert np.degrees(flight.pointing_error[0]) == pytest.approx(90.0)
        assert np.degrees(flight.pointing_error[-1]) < 1e-4
        assert 5.0 < flight.peak_torque < SHORT.max_torque


def test_dcsim_holds_the_position_only_when_asked(dcsim_rows):
    drift = np.linalg.norm(SHORT.initial_velocity) * SHORT.duration
    assert dcsim_rows[False].position_error[-1] == pytest.approx(drift, rel=1e-6)
    held = dcsim_rows[True].position_error
    assert 0.05 < held.max() < 0.5 and held[-1] < 1e-3


def test_dcsim_slews_on_its_wheels_and_they_keep_the_momentum(dcsim_rows, dcsim_wheels):
    flight = dcsim_wheels
    assert flight.times == pytest.approx(dcsim_rows[False].times)
    assert np.degrees(flight.pointing_error[0]) == pytest.approx(90.0)
    assert np.degrees(flight.pointing_error[-1]) < 1e-4
    assert flight.wheel_speed.shape == (len(flight.times), 4)
    assert np.all(flight.wheel_speed[0] == 0.0)
    # the commanded torque is within what the wheels give; no wheel near its limit
    assert 5.0 < flight.peak_torque < peers.torque_limit(SHORT, "wheels")
    assert 20.0 < flight.peak_wheel_speed < 0.5 * SHORT.wheel_max_momentum / SHORT.wheel_inertia
    # at rest at the goal the wheels hold all of the initial angular momentum I ω0
    initial = 0.4 * SHORT.mass * SHORT.radius**2 * np.asarray(SHORT.initial_angular_velocity)
    assert wheel_momentum_in_world(flight, -1) == pytest.approx(initial, abs=1e-6)
    # the wheels deliver the commanded torque: the slew is the ideal torque's, but for
    # the gyroscopic torque of the momentum they carry (0.08 degrees apart at most)
    assert np.degrees(peers.largest_gap(flight, dcsim_rows[False])) < 0.2


def test_dcsim_slews_on_its_thruster_couples_without_pushing(dcsim_rows, thruster_rows):
    flight = thruster_rows[0]
    assert flight.times == pytest.approx(dcsim_rows[False].times)
    assert flight.wheel_speed.shape == (len(flight.times), 0)
    assert np.degrees(flight.pointing_error[-1]) < 1e-4
    assert 5.0 < flight.peak_torque < peers.torque_limit(SHORT, "thrusters") == 20.0
    # the couples give no force: the free flyer drifts as with the ideal torque
    assert flight.position_error == pytest.approx(dcsim_rows[False].position_error, abs=1e-9)
    # pulses from the period's start give the mean torque a little early: 0.5 degrees
    assert np.degrees(peers.largest_gap(flight, dcsim_rows[False])) < 1.0


def test_mrps_and_quaternions_convert_both_ways():
    rng = np.random.default_rng(7)
    quaternions = rng.normal(size=(20, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1, keepdims=True)
    sigma = mrp_from_quaternion(quaternions)
    assert np.all(np.linalg.norm(sigma, axis=1) <= 1.0 + 1e-12)
    back = quaternion_from_mrp(sigma)
    assert np.abs(np.sum(back * quaternions, axis=1)) == pytest.approx(np.ones(20))


@needs_basilisk
def test_mrps_follow_basilisks_attitude_convention():
    from Basilisk.utilities import RigidBodyKinematics as rbk

    from dcsim.geometry import rotate

    q = np.asarray(SHORT.initial_attitude)
    body_to_world = np.column_stack([rotate(q, axis) for axis in np.eye(3)])
    assert np.asarray(rbk.MRP2C(mrp_from_quaternion(q))) == pytest.approx(body_to_world.T)


@needs_basilisk
def test_basilisk_flies_the_same_slew(dcsim_rows, basilisk_rows):
    for hold in (False, True):
        ours, theirs = dcsim_rows[hold], basilisk_rows[hold]
        assert theirs.times == pytest.approx(ours.times)
        assert theirs.pointing_error[0] == pytest.approx(ours.pointing_error[0], abs=1e-9)
        assert np.degrees(theirs.pointing_error[-1]) < 1e-4
        # MRP feedback is a little stiffer than the rotation-vector law at large angles
        gap = np.degrees(peers.largest_gap(ours, theirs))
        assert 0.1 < gap < 3.0
        assert theirs.peak_torque == pytest.approx(ours.peak_torque, rel=0.15)


@needs_basilisk
def test_basilisk_flies_the_same_wheel_slew(dcsim_wheels, basilisk_wheels):
    ours, theirs = dcsim_wheels, basilisk_wheels
    assert theirs.times == pytest.approx(ours.times)
    assert theirs.wheel_speed.shape == ours.wheel_speed.shape
    assert theirs.wheel_speed[0] == pytest.approx(ours.wheel_speed[0], abs=1e-12)
    # the same final pointing: 1.30e-6 and 1.14e-6 degrees after 40 s; the residues of
    # the two laws' transients (1.4 degrees apart in the slew, as without wheels) decay
    # alike and differ by 1.6e-7 degrees
    final = np.degrees([ours.pointing_error[-1], theirs.pointing_error[-1]])
    assert final.max() < 1e-5
    assert abs(final[0] - final[1]) < 1e-6
    gap = np.degrees(peers.largest_gap(ours, theirs))
    assert 0.1 < gap < 3.0
    # the stiffer MRP law spins the wheels up a little faster: 81.0 and 83.9 rad/s
    assert theirs.peak_wheel_speed == pytest.approx(ours.peak_wheel_speed, rel=0.05)
    # at rest the wheels hold the same momentum, which depends only on the total angular
    # momentum and the attitude: 6e-7 rad/s apart after 40 s; a wheel started with
    # Basilisk's default Ω = 0, or the hub's inertia without the wheels', moves them by
    # 0.03 rad/s
    assert theirs.wheel_speed[-1] == pytest.approx(ours.wheel_speed[-1], abs=1e-5)


@needs_basilisk
def test_basilisk_flies_the_thruster_slew_roughly_as_dcsim_does(thruster_rows):
    ours, theirs = thruster_rows
    assert theirs.times == pytest.approx(ours.times)
    assert theirs.position_error == pytest.approx(ours.position_error, abs=1e-9)
    # Basilisk's thrusters first fire at 0.2 s and switch at the integrator's stages:
    # its slew is 2.47 degrees from dcsim's at most and ends in a limit cycle of about
    # 0.03 degrees (dcsim's: 1.2e-6 degrees after 40 s)
    assert 1.0 < np.degrees(peers.largest_gap(ours, theirs)) < 4.0
    tail = np.degrees(theirs.pointing_error[-len(theirs.times) // 10 :])
    assert 1e-3 < tail.max() < 0.1
    assert np.degrees(ours.pointing_error[-1]) < 1e-5


@needs_basilisk
def test_basilisk_holds_the_position_as_dcsim_does(dcsim_rows, basilisk_rows):
    free, held = basilisk_rows[False], basilisk_rows[True]
    assert free.position_error == pytest.approx(
        dcsim_rows[False].position_error, rel=1e-4, abs=1e-6
    )
    assert held.position_error == pytest.approx(dcsim_rows[True].position_error, abs=2e-3)
    assert held.position_error[-1] < 1e-3


def test_the_table_has_both_rows_and_the_verdict(registry):
    result = peers.bench_peers(1.0, 1, progress=lambda line: None)
    table = peers.markdown_table(result).splitlines()
    assert [line.split("|")[1].strip() for line in table[2:]] == [
        "attitude slew",
        "slew + position hold",
        "slew on 4 wheels",
        "slew on 12 thrusters",
    ]
    text = peers.notes(result) + "\n" + peers.verdict(result)
    if BASILISK is None:
        for line in table[2:]:
            cells = [cell.strip() for cell in line.strip("| ").split("|")]
            assert len(cells) == 10 and float(cells[8]) > 0 and cells[9] in ("yes", "no")
        assert "target (dcsim's attitude loop within 3× of Basilisk's wall time): " in text
        assert "target (dcsim's wheel slew within 3× of Basilisk's wall time): " in text
        assert "final wheel speeds differ by at most" in text
    else:
        assert f"Basilisk was not flown: {BASILISK}" in text
        assert text.count("not measured, Basilisk was not flown") == 2
    assert "- slew on 4 wheels: 4 wheels in a pyramid" in text
    assert "peak wheel speed (momentum / wheel inertia) dcsim " in text
    assert "no wheel saturates" in text
    assert "- slew on 12 thrusters: six opposed couples 1 m from the centre of mass" in text


def test_the_command_prints_the_table_and_draws_the_plot(dcsim_cli, tmp_path):
    plot = tmp_path / "peers.png"
    result = dcsim_cli("bench", "peers", "--duration", "2", "--repeats", "1", "--plot", str(plot))
    assert result.returncode == 0, result.stderr
    assert "| attitude slew |" in result.stdout
    assert "| slew + position hold |" in result.stdout
    assert "| slew on 4 wheels |" in result.stdout
    assert "| slew on 12 thrusters |" in result.stdout
    assert "attitude slew, run 1/1: dcsim" in result.stderr
    if BASILISK is not None:
        assert "Basilisk is not flown: " in result.stderr
    assert plot.stat().st_size > 10_000


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--basilisk-step", "0.03", "0.03 s does not divide the 0.1 s control period"),
        ("--repeats", "0", "0 is not in the range x>=1"),
        ("--duration", "0.5", "0.5 is not in the range 1.0<=x<=86400.0"),
    ],
)
def test_bad_options_are_refused_without_a_traceback(dcsim_cli, option, value, message):
    result = dcsim_cli("bench", "peers", option, value)
    assert result.returncode == 2
    assert message in result.stderr
    assert "Traceback" not in result.stderr
