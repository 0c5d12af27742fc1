"""Tests of the LQR controller: dcsim's conformance suite, then its own law."""

import pytest
from dcsim_lqr import LQRController, LQRParams, lqr_gains

from dcsim.testing import ControllerContract


class TestConformance(ControllerContract):
    plugin = LQRController


def test_gains_solve_the_riccati_equation_of_the_double_integrator():
    # For the double integrator with Q = diag(q1, q2), R = r the LQR gains are
    # kp = sqrt(q1 / r) and kd = sqrt(q2 / r + 2 kp).
    params = LQRParams(position_error=2.0, velocity_error=0.5, acceleration=0.1)
    kp, kd = lqr_gains(params)
    assert kp == pytest.approx((0.25 / 100.0) ** 0.5)
    assert kd == pytest.approx((4.0 / 100.0 + 2 * kp) ** 0.5)
