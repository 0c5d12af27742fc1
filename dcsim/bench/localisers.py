"""``dcsim bench localisers``: localisers against the posterior Cramér–Rao bound.

The problem follows the source thesis's setting: the three nearest of eight beacons
report a range, drawn by the world's ``beacon-range`` sensor model
(:class:`~dcsim.world.sensors.beacon_ranges.BeaconRangeSensor`) with white noise
``sigma``; the collector manoeuvres under commanded accelerations plus white thrust
noise ``acceleration_sigma`` (which the filters are told). Each localiser flies the same
Monte Carlo set of runs under each range model of :data:`CASES` and is told only the
white ``sigma``, as in a run:

- ``white``: white noise alone;
- ``biased``: a constant bias of 2σ added to every range;
- ``outliers``: 5 % of the ranges get an extra Gaussian error of standard deviation 20σ.

The root-mean-square position error over the runs is compared, step by step, with the
posterior Cramér–Rao lower bound (PCRB, Tichavský et al. 1998) of that trajectory,
geometry and range model:

    J₀ = P₀⁻¹,   J_{k+1} = (Q + F J_k⁻¹ Fᵀ)⁻¹ + I_r H_{k+1}ᵀ H_{k+1}

with ``H`` the range Jacobian at the true state and the beacons reported then (one row
per range) and ``I_r`` the Fisher information of one range's error, m⁻²; the bound on the
position RMSE is ``sqrt(trace of the position block of J⁻¹)``, averaged over the runs'
true trajectories. Per case:

- white: ``I_r = 1/σ²``;
- biased: the bias ``b`` is an unknown constant in the state, ``[p, v, b]``, with a prior
  ``N(0, σ_b²)``, ``σ_b`` = 2σ (the size of the bias flown); ``F`` and ``Q`` keep it
  constant and each row of ``H`` is ``[uᵀ, 0, 0, 0, 1]`` with ``u`` the unit vector from
  the beacon to the collector. As ``σ_b → 0`` the bound is the white one. The localisers
  ignore the bias: their ratio to this bound shows what that costs. (Being Bayesian,
  the bound holds on average over the bias's prior, not for each value of it.)
- outliers: the error of a range is the contaminated Gaussian
  ``p(x) = ε N(x; 0, σ² + s²) + (1 − ε) N(x; 0, σ²)`` (ε the outlier probability, s the
  outlier size), whose Fisher information

      I_r = ∫ p'(x)² / p(x) dx = 1/σ_eff²

  is computed once by quadrature (:func:`range_information`); it is at most 1/σ² (the
  information of a sum of independent errors is at most that of either), and equals it
  at ε = 0.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.integrate import quad
from scipy.special import logsumexp, softmax

from dcsim.bench.figures import pyplot, save
from dcsim.errors import DcsimError
from dcsim.messages import BeaconRange, MotionInput, Prior, SensedTruth, SensorSetup
from dcsim.registry.discovery import PluginRegistry
from dcsim.registry.interfaces import Localiser
from dcsim.world.sensors.beacon_ranges import BeaconRangeSensor

BEACONS = np.array(
    [
        [300.0, 0.0, 50.0], [-300.0, 0.0, -50.0], [0.0, 300.0, -80.0], [0.0, -300.0, 80.0],
        [200.0, 200.0, 250.0], [-200.0, -200.0, 250.0],
        [200.0, -200.0, -250.0], [-200.0, 200.0, -250.0],
    ]
)  # fmt: skip
"""Beacon positions of the benchmark, m."""

DT = 0.5
"""Step between range measurements, s."""

_LEVEL = np.array([0.0, 0.0, 0.0, 1.0])
"""The collector's attitude (the ranges do not depend on it), ``[x, y, z, w]``."""


@dataclass(frozen=True)
class RangeCase:
    """One range model the localisers fly, its sizes in units of the white noise σ.

    Attributes
    ----------
    name : str
        The case's name (``--ranges``).
    bias : float
        Constant added to every range, in σ.
    outlier_probability : float
        Probability that a range is an outlier.
    outlier_size : float
        Standard deviation of an outlier's extra Gaussian error, in σ.
    bias_prior : float
        Standard deviation of the bias's prior in the bound, in σ; 0 when the bound's
        state has no bias.
    """

    name: str
    bias: float = 0.0
    outlier_probability: float = 0.0
    outlier_size: float = 1.0
    bias_prior: float = 0.0

    def sensor_params(self, sigma: float) -> dict[str, float]:
        """The ``beacon-range`` model's parameters for white noise ``sigma`` (m)."""
        return {
            "bias": self.bias * sigma,
            "outlier_probability": self.outlier_probability,
            "outlier_size": self.outlier_size * sigma,
        }

    def bound(self, runs: Sequence[Run], sigma: float, acceleration_sigma: float) -> np.ndarray:
        """The case's PCRB on the position RMSE (m) at each step, over ``runs``.

        Parameters
        ----------
        runs : sequence of Run
            The true trajectories and the beacons reported.
        sigma : float
            White range noise, m.
        acceleration_sigma : float
            Thrust noise, m/s².
        """
        information = range_information(sigma, self.outlier_probability, self.outlier_size * sigma)
        bias_prior_sigma = self.bias_prior * sigma
        bounds = [pcrb(run, information, acceleration_sigma, bias_prior_sigma) for run in runs]
        return np.sqrt(np.mean(bounds, axis=0))


CASES = {
    case.name: case
    for case in (
        RangeCase("white"),
        RangeCase("biased", bias=2.0, bias_prior=2.0),
        RangeCase("outliers", outlier_probability=0.05, outlier_size=20.0),
    )
}
"""The range models benchmarked, by name."""


def range_cases(names: Sequence[str]) -> list[RangeCase]:
    """The cases named, in order.

    Raises
    ------
    DcsimError
        When a name is not one of :data:`CASES`.
    """
    unknown = [name for name in names if name not in CASES]
    if unknown:
        raise DcsimError(f"--ranges: unknown {', '.join(unknown)}; use {', '.join(CASES)}")
    return [CASES[name] for name in names]


def range_information(sigma: float, outlier_probability: float, outlier_size: float) -> float:
    """Fisher information of one range's contaminated Gaussian error, m⁻².

    ``∫ p'(x)²/p(x) dx`` for ``p = ε N(0, σ² + s²) + (1 − ε) N(0, σ²)``, by adaptive
    quadrature in units of σ (the information scales as 1/σ²).

    Parameters
    ----------
    sigma : float
        White noise σ, m.
    outlier_probability : float
        ε, in [0, 1].
    outlier_size : float
        s, the outliers' extra standard deviation, m.
    """
    weights = np.array([1.0 - outlier_probability, outlier_probability])
    variances = np.array([1.0, 1.0 + (outlier_size / sigma) ** 2])[weights > 0]
    log_weights = np.log(weights[weights > 0]) - 0.5 * np.log(2.0 * np.pi * variances)

    def integrand(x: float) -> float:
        # p'/p = -x Σ_i π_i/v_i with π_i each component's share of p(x): no 0/0 where
        # the narrow component underflows
        logs = log_weights - 0.5 * x * x / variances
        score = -x * float(softmax(logs) @ (1.0 / variances))
        return score * score * float(np.exp(logsumexp(logs)))

    reach = 12.0 * float(np.sqrt(variances.max()))
    value, _ = quad(integrand, -reach, reach, points=(-3.0, 0.0, 3.0), limit=200)
    return value / sigma**2


@dataclass(frozen=True)
class Run:
    """One Monte Carlo run: the prior, and per step the input, ranges and truth."""

    prior: Prior
    motions: list[MotionInput]
    ranges: list[tuple[BeaconRange, ...]]
    states: np.ndarray  # (steps, 6) true position and velocity


def make_run(
    seed: int,
    steps: int,
    sigma: float,
    acceleration_sigma: float,
    case: RangeCase = CASES["white"],
    nearest: int = 3,
) -> Run:
    """A manoeuvring collector and the ranges the ``beacon-range`` model gives it.

    The motion and the sensor draw from two generators spawned from ``seed``: every
    case of one seed flies the same trajectory and the same white noise.

    Parameters
    ----------
    seed : int
        The run's seed.
    steps : int
        Updates, ``DT`` apart.
    sigma : float
        White range noise, m.
    acceleration_sigma : float
        Thrust noise, m/s².
    case : RangeCase
        The range model.
    nearest : int
        Ranges per reading (the nearest beacons).
    """
    motion_seed, sensor_seed = np.random.SeedSequence(seed).spawn(2)
    rng = np.random.default_rng(motion_seed)
    sensor = BeaconRangeSensor(case.sensor_params(sigma), np.random.default_rng(sensor_seed))
    sensor.reset(
        SensorSetup(
            control_period=DT, beacons=BEACONS, beacon_noise=sigma, beacon_report_nearest=nearest
        )
    )
    position, velocity = np.array([-60.0, 40.0, 10.0]), np.array([0.5, -0.2, 0.05])
    prior = Prior(
        position=position + rng.normal(0.0, 20.0, 3),
        position_sigma=20.0,
        velocity=velocity + rng.normal(0.0, 0.2, 3),
        velocity_sigma=0.2,
    )
    motions, ranges, states = [], [], []
    for k in range(steps):
        commanded = 0.02 * np.array([np.sin(0.02 * k), np.cos(0.015 * k), np.sin(0.01 * k + 1.0)])
        actual = commanded + rng.normal(0.0, acceleration_sigma, 3)
        position = position + velocity * DT + 0.5 * actual * DT**2
        velocity = velocity + actual * DT
        truth = SensedTruth(
            time=(k + 1) * DT,
            position=position,
            velocity=velocity,
            attitude=_LEVEL,
            angular_velocity=np.zeros(3),
        )
        measured = sensor.measure(truth)
        assert isinstance(measured, tuple)  # a beacon-range model answers ranges
        motions.append(MotionInput(commanded))
        ranges.append(measured)
        states.append(np.concatenate([position, velocity]))
    return Run(prior, motions, ranges, np.array(states))


def pcrb(
    run: Run, information_per_range: float, acceleration_sigma: float, bias_prior_sigma: float = 0.0
) -> np.ndarray:
    """Posterior Cramér–Rao bound on the position MSE (m²) at each step of one run.

    Parameters
    ----------
    run : Run
        The true trajectory and the beacons reported at each step.
    information_per_range : float
        Fisher information of one range's error, m⁻² (1/σ² for white noise).
    acceleration_sigma : float
        Thrust noise, m/s².
    bias_prior_sigma : float
        Standard deviation of the prior of an unknown constant bias on every range, m;
        0 for ranges without one (the state is then position and velocity alone).
    """
    eye, zero = np.eye(3), np.zeros((3, 3))
    f = np.block([[eye, DT * eye], [zero, eye]])
    b = np.vstack([0.5 * DT**2 * eye, DT * eye])
    q = acceleration_sigma**2 * b @ b.T
    variances = [run.prior.position_sigma**2] * 3 + [run.prior.velocity_sigma**2] * 3
    biased = bias_prior_sigma > 0
    if biased:  # the bias is a constant of the state: F keeps it, Q does not move it
        f, q = np.pad(f, (0, 1)), np.pad(q, (0, 1))
        f[-1, -1] = 1.0
        variances.append(bias_prior_sigma**2)
    information = np.diag(1.0 / np.array(variances))
    bounds = []
    for state, ranges in zip(run.states, run.ranges, strict=True):
        predicted = q + f @ np.linalg.inv(information) @ f.T
        beacons = np.array([r.beacon_position for r in ranges]).reshape(-1, 3)
        rows = (state[:3] - beacons) / np.linalg.norm(state[:3] - beacons, axis=1)[:, None]
        h = np.hstack([rows, np.zeros_like(rows), np.ones((len(rows), int(biased)))])
        information = np.linalg.inv(predicted) + information_per_range * h.T @ h
        bounds.append(np.trace(np.linalg.inv(information)[:3, :3]))
    return np.array(bounds)


@dataclass
class LocaliserResult:
    """One localiser's errors over all runs and its update latencies."""

    label: str
    errors: list[np.ndarray] = field(default_factory=list)  # per run, (steps,)
    converged_at: list[float] = field(default_factory=list)  # per run, s (inf if never)
    latencies: list[float] = field(default_factory=list)  # s per step

    def rmse(self) -> np.ndarray:
        """Root-mean-square position error over runs, per step (m)."""
        return np.sqrt(np.mean(np.square(self.errors), axis=0))


@dataclass(frozen=True)
class CaseResult:
    """Every localiser's result under one range model, with the model's bound.

    Attributes
    ----------
    case : RangeCase
        The range model.
    bound : ndarray (steps,)
        The PCRB on the position RMSE per step, over the runs, m.
    results : list of LocaliserResult
        One per localiser.
    """

    case: RangeCase
    bound: np.ndarray
    results: list[LocaliserResult]


def fly(
    registry: PluginRegistry,
    name: str,
    params: dict[str, Any],
    run: Run,
    seed: int,
    result: LocaliserResult,
) -> None:
    """Run one localiser through one run, recording errors, convergence and latency."""
    localiser = registry.create("localiser", name, params, np.random.default_rng(seed))
    assert isinstance(localiser, Localiser)  # the registry files plugins by their class's kind
    localiser.reset(run.prior, 0.0)
    errors, converged_at = [], np.inf
    for k, (motion, ranges) in enumerate(zip(run.motions, run.ranges, strict=True)):
        start = time.perf_counter()
        localiser.predict(motion, DT)
        localiser.update(ranges)
        estimate = localiser.estimate()
        result.latencies.append(time.perf_counter() - start)
        errors.append(np.linalg.norm(estimate.position - run.states[k, :3]))
        if estimate.converged and converged_at == np.inf:
            converged_at = (k + 1) * DT
    result.errors.append(np.array(errors))
    result.converged_at.append(converged_at)


def candidates(acceleration_sigma: float) -> list[tuple[str, str, dict[str, Any], int]]:
    """(label, plugin, parameters, runs cap) of every localiser benchmarked.

    The particle filters use the thesis's weights with their default knots, and, for
    10k particles, the Gaussian likelihood as well, resampling every step or only when
    the effective sample size falls below 30 % of the particles.
    """
    sspf = {"motion_sigma": acceleration_sigma}
    return [
        ("trilateration", "trilateration", {}, 10**6),
        ("ekf", "ekf", {"acceleration_sigma": acceleration_sigma}, 10**6),
        ("ukf", "ukf", {"acceleration_sigma": acceleration_sigma}, 10**6),
        ("sspf 1k", "sspf", {**sspf, "particles": 1_000}, 10**6),
        ("sspf 10k", "sspf", {**sspf, "particles": 10_000}, 10**6),
        ("sspf 100k", "sspf", {**sspf, "particles": 100_000}, 2),
        (
            "sspf 10k gaussian",
            "sspf",
            {**sspf, "particles": 10_000, "likelihood": "gaussian"},
            10**6,
        ),
        (
            "sspf 10k gaussian, ESS",
            "sspf",
            {**sspf, "particles": 10_000, "likelihood": "gaussian", "resample_below": 0.3},
            10**6,
        ),
    ]


def bench_localisers(
    runs: int,
    steps: int,
    sigma: float,
    acceleration_sigma: float,
    cases: Sequence[RangeCase] = tuple(CASES.values()),
    progress: Callable[[str], None] = print,
) -> list[CaseResult]:
    """Fly every localiser under every range model.

    Parameters
    ----------
    runs, steps : int
        Monte Carlo runs, and updates per run (``DT`` apart).
    sigma : float
        White range noise, m (what the localisers are told).
    acceleration_sigma : float
        Thrust noise, m/s² (the filters are told).
    cases : sequence of RangeCase
        The range models, each flown on the same seeds.
    progress : callable
        Takes a line after each localiser.
    """
    registry = PluginRegistry.discover()
    flown = []
    for case in cases:
        problems = [make_run(seed, steps, sigma, acceleration_sigma, case) for seed in range(runs)]
        bound = case.bound(problems, sigma, acceleration_sigma)
        results = []
        for label, name, params, cap in candidates(acceleration_sigma):
            result = LocaliserResult(label)
            for seed, run in enumerate(problems[:cap]):
                fly(registry, name, params, run, seed, result)
            results.append(result)
            progress(
                f"{case.name}, {label}: {len(result.errors)} runs, "
                f"median update {1e3 * np.median(result.latencies):.2f} ms"
            )
        flown.append(CaseResult(case, bound, results))
    return flown


def _second_half(rmse: np.ndarray) -> float:
    """RMS over the second half of a per-step RMSE, m."""
    return float(np.sqrt(np.mean(rmse[len(rmse) // 2 :] ** 2)))


def markdown_table(cases: Sequence[CaseResult]) -> str:
    """Per range model: the bound, then each localiser's RMSE over the second half, its
    ratio to that model's bound, convergence and latency."""
    lines = [
        "| ranges | localiser | runs | RMSE, 2nd half [m] | × PCRB | converged at [s] (median) "
        "| update median [ms] | update p95 [ms] |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for flown in cases:
        bound = _second_half(flown.bound)
        lines.append(f"| {flown.case.name} | PCRB | – | {bound:.4f} | 1.00 | – | – | – |")
        for r in flown.results:
            rmse = _second_half(r.rmse())
            lat = np.array(r.latencies) * 1e3
            lines.append(
                f"| {flown.case.name} | {r.label} | {len(r.errors)} | {rmse:.4f} | "
                f"{rmse / bound:.2f} | {np.median(r.converged_at):.1f} | "
                f"{np.median(lat):.2f} | {np.percentile(lat, 95):.2f} |"
            )
    return "\n".join(lines)


def plot(cases: Sequence[CaseResult], path: Path) -> None:
    """RMSE over time of every localiser with the bound, log scale, one panel per range
    model."""
    plt = pyplot()

    figure, axes = plt.subplots(
        len(cases), 1, figsize=(10, 4.2 * len(cases)), sharex=True, squeeze=False
    )
    for axis, flown in zip(axes[:, 0], cases, strict=True):
        times = DT * (np.arange(len(flown.bound)) + 1)
        for r in flown.results:
            axis.semilogy(times, r.rmse(), lw=1.2, label=f"{r.label} ({len(r.errors)} runs)")
        axis.semilogy(times, flown.bound, "k--", lw=2, label="posterior Cramér–Rao bound")
        axis.set(ylabel="position RMSE [m]", title=f"{flown.case.name} ranges")
        axis.grid(alpha=0.3, which="both")
    axes[0, 0].legend(fontsize=8)
    axes[-1, 0].set_xlabel("time [s]")
    figure.suptitle("Localisers on the three-nearest-beacons problem")
    save(figure, path, dpi=110)
