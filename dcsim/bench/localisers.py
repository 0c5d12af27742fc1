"""``dcsim bench localisers``: localisers against the posterior Cramér–Rao bound.

The problem follows the source thesis's setting: the three nearest of eight beacons
report a range with Gaussian noise ``sigma``; the collector manoeuvres under commanded
accelerations plus white thrust noise ``acceleration_sigma`` (which the filters are told).
Each localiser flies the same Monte Carlo set of runs; the root-mean-square position
error over the runs is compared, step by step, with the posterior Cramér–Rao lower bound
(PCRB, Tichavský et al. 1998) of that trajectory and geometry:

    J₀ = P₀⁻¹,   J_{k+1} = (Q + F J_k⁻¹ Fᵀ)⁻¹ + H_{k+1}ᵀ R⁻¹ H_{k+1}

with ``H`` the range Jacobian at the true state and the beacons reported then; the
bound on the position RMSE is ``sqrt(trace of the position block of J⁻¹)``, averaged
over the runs' true trajectories.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from dcsim.bench.figures import pyplot, save
from dcsim.messages import BeaconRange, MotionInput, Prior
from dcsim.registry.discovery import PluginRegistry
from dcsim.registry.interfaces import Localiser

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


@dataclass(frozen=True)
class Run:
    """One Monte Carlo run: the prior, and per step the input, ranges and truth."""

    prior: Prior
    motions: list[MotionInput]
    ranges: list[list[BeaconRange]]
    states: np.ndarray  # (steps, 6) true position and velocity


def make_run(
    seed: int, steps: int, sigma: float, acceleration_sigma: float, nearest: int = 3
) -> Run:
    """A manoeuvring collector and its noisy ranges to the nearest beacons."""
    rng = np.random.default_rng(seed)
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
        distances = np.linalg.norm(BEACONS - position, axis=1)
        order = np.argsort(distances)[:nearest]
        noisy = distances[order] + rng.normal(0.0, sigma, nearest)
        motions.append(MotionInput(commanded))
        ranges.append(
            [
                BeaconRange(int(i), BEACONS[i], float(r), sigma)
                for i, r in zip(order, noisy, strict=True)
            ]
        )
        states.append(np.concatenate([position, velocity]))
    return Run(prior, motions, ranges, np.array(states))


def pcrb(run: Run, sigma: float, acceleration_sigma: float) -> np.ndarray:
    """Posterior Cramér–Rao bound on the position MSE (m²) at each step of one run."""
    eye, zero = np.eye(3), np.zeros((3, 3))
    f = np.block([[eye, DT * eye], [zero, eye]])
    b = np.vstack([0.5 * DT**2 * eye, DT * eye])
    q = acceleration_sigma**2 * b @ b.T
    information = np.linalg.inv(
        np.diag([run.prior.position_sigma**2] * 3 + [run.prior.velocity_sigma**2] * 3)
    )
    bounds = []
    for state, ranges in zip(run.states, run.ranges, strict=True):
        predicted = q + f @ np.linalg.inv(information) @ f.T
        beacons = np.array([r.beacon_position for r in ranges])
        rows = (state[:3] - beacons) / np.linalg.norm(state[:3] - beacons, axis=1)[:, None]
        h = np.hstack([rows, np.zeros_like(rows)])
        information = np.linalg.inv(predicted) + h.T @ h / sigma**2
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


def fly(
    registry: PluginRegistry, name: str, params: dict, run: Run, seed: int, result: LocaliserResult
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


def candidates(acceleration_sigma: float) -> list[tuple[str, str, dict, int]]:
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
    progress: Callable[[str], None] = print,
) -> tuple[np.ndarray, list[LocaliserResult]]:
    """Fly every localiser; return the bound's RMSE per step and the results."""
    registry = PluginRegistry.discover()
    problems = [make_run(seed, steps, sigma, acceleration_sigma) for seed in range(runs)]
    bound = np.sqrt(np.mean([pcrb(run, sigma, acceleration_sigma) for run in problems], axis=0))
    results = []
    for label, name, params, cap in candidates(acceleration_sigma):
        result = LocaliserResult(label)
        for seed, run in enumerate(problems[:cap]):
            fly(registry, name, params, run, seed, result)
        results.append(result)
        progress(
            f"{label}: {len(result.errors)} runs, "
            f"median update {1e3 * np.median(result.latencies):.2f} ms"
        )
    return bound, results


def markdown_table(bound: np.ndarray, results: list[LocaliserResult]) -> str:
    """Steady-state RMSE (second half), its ratio to the bound, convergence and latency."""
    half = len(bound) // 2
    bound_ss = float(np.sqrt(np.mean(bound[half:] ** 2)))
    lines = [
        "| localiser | runs | RMSE, 2nd half [m] | × PCRB | converged at [s] (median) "
        "| update median [ms] | update p95 [ms] |",
        "|---|---:|---:|---:|---:|---:|---:|",
        f"| PCRB | – | {bound_ss:.4f} | 1.00 | – | – | – |",
    ]
    for r in results:
        rmse = float(np.sqrt(np.mean(r.rmse()[half:] ** 2)))
        lat = np.array(r.latencies) * 1e3
        lines.append(
            f"| {r.label} | {len(r.errors)} | {rmse:.4f} | {rmse / bound_ss:.2f} | "
            f"{np.median(r.converged_at):.1f} | {np.median(lat):.2f} | "
            f"{np.percentile(lat, 95):.2f} |"
        )
    return "\n".join(lines)


def plot(bound: np.ndarray, results: list[LocaliserResult], path) -> None:
    """RMSE over time of every localiser with the bound, log scale."""
    plt = pyplot()

    times = DT * (np.arange(len(bound)) + 1)
    figure, axis = plt.subplots(figsize=(10, 5.5))
    for r in results:
        axis.semilogy(times, r.rmse(), lw=1.2, label=f"{r.label} ({len(r.errors)} runs)")
    axis.semilogy(times, bound, "k--", lw=2, label="posterior Cramér–Rao bound")
    axis.set(
        xlabel="time [s]",
        ylabel="position RMSE [m]",
        title="Localisers on the three-nearest-beacons problem",
    )
    axis.grid(alpha=0.3, which="both")
    axis.legend(fontsize=8)
    save(figure, path, dpi=110)
