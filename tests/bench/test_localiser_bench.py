"""The localiser bench: its runs' ranges come from the beacon-range sensor model, and
each range model's bound reduces to the white one where it should."""

from __future__ import annotations

from math import erf, sqrt

import numpy as np
import pytest

from dcsim.bench.localisers import (
    CASES,
    bench_localisers,
    candidates,
    make_run,
    markdown_table,
    pcrb,
    plot,
    range_cases,
    range_information,
)
from dcsim.errors import DcsimError

SIGMA = 0.5
"""White range noise of the tests, m (not 1, so that sizes in σ are scaled)."""

ACCELERATION_SIGMA = 0.005
"""Thrust noise of the tests, m/s²."""


def residuals(case: str, steps: int, seed: int = 0) -> np.ndarray:
    """Every range of one run less its true distance, m."""
    run = make_run(seed, steps, SIGMA, ACCELERATION_SIGMA, CASES[case])
    return np.array(
        [
            r.range - np.linalg.norm(r.beacon_position - state[:3])
            for ranges, state in zip(run.ranges, run.states, strict=True)
            for r in ranges
        ]
    )


def test_the_bias_augmented_bound_is_the_white_one_as_the_bias_prior_narrows():
    run = make_run(3, 120, SIGMA, ACCELERATION_SIGMA)
    white = pcrb(run, 1 / SIGMA**2, ACCELERATION_SIGMA)
    gaps = [
        np.max(np.abs(pcrb(run, 1 / SIGMA**2, ACCELERATION_SIGMA, prior) / white - 1))
        for prior in (1e-3, 1e-4, 1e-5, 1e-6)
    ]
    # the bias's prior variance is what the bound gains: a tenth of σ_b, a hundredth of it
    assert np.array(gaps[:-1]) / gaps[1:] == pytest.approx(100, rel=0.05)
    assert gaps[-1] < 1e-9
    wide = pcrb(run, 1 / SIGMA**2, ACCELERATION_SIGMA, bias_prior_sigma=2 * SIGMA)
    assert np.all(wide >= white * (1 - 1e-12)) and wide[-1] > 1.01 * white[-1]


@pytest.mark.parametrize(("sigma", "size"), [(1.0, 1.0), (0.5, 10.0), (2.0, 40.0)])
def test_the_contaminated_information_is_the_white_one_without_outliers(sigma, size):
    assert range_information(sigma, 0.0, size) == pytest.approx(1 / sigma**2, rel=1e-9)
    # all outliers: a Gaussian of variance σ² + s²
    assert range_information(sigma, 1.0, size) == pytest.approx(1 / (sigma**2 + size**2), rel=1e-9)


@pytest.mark.parametrize("probability", [0.01, 0.05, 0.2, 0.5, 0.9])
@pytest.mark.parametrize("size", [0.5, 3.0, 20.0])
def test_the_contaminated_information_is_below_the_white_one(probability, size):
    information = range_information(SIGMA, probability, size * SIGMA)
    assert 0 < information < 1 / SIGMA**2
    assert information >= 1 / (SIGMA**2 + (size * SIGMA) ** 2)


def test_the_biased_case_s_ranges_are_the_white_ones_plus_the_bias():
    white, biased = residuals("white", 400), residuals("biased", 400)
    assert biased - white == pytest.approx(np.full(len(white), 2 * SIGMA), abs=1e-9)
    assert np.mean(biased) == pytest.approx(2 * SIGMA, abs=4 * SIGMA / np.sqrt(len(biased)))
    assert np.std(white) == pytest.approx(SIGMA, rel=0.1)


def test_the_outlier_case_s_ranges_have_outliers_at_their_rate():
    errors = residuals("outliers", 2000)
    case = CASES["outliers"]
    spread = np.hypot(1.0, case.outlier_size)  # an outlier's whole error, in σ
    # beyond 6σ only outliers reach (the white noise alone, with probability 2e-9);
    # how many reach 20σ tells their size
    for reach in (6.0, 20.0):
        far = np.mean(np.abs(errors) > reach * SIGMA)
        expected = case.outlier_probability * 2 * (1 - _normal_cdf(reach / spread))
        assert far == pytest.approx(expected, abs=4 * np.sqrt(expected / len(errors)))


def _normal_cdf(x: float) -> float:
    """The standard normal distribution function."""
    return 0.5 * (1 + erf(x / sqrt(2)))


@pytest.mark.parametrize("name", list(CASES))
def test_each_case_runs_on_a_tiny_instance(name, tmp_path):
    lines: list[str] = []
    flown = bench_localisers(1, 10, 1.0, ACCELERATION_SIGMA, range_cases([name]), lines.append)
    labels = [label for label, *_ in candidates(ACCELERATION_SIGMA)]
    assert len(lines) == len(labels) and lines[0].startswith(f"{name}, trilateration: 1 runs")
    rows = [line.split("|")[1:-1] for line in markdown_table(flown).splitlines()[2:]]
    assert [row[1].strip() for row in rows] == ["PCRB", *labels]
    assert {row[0].strip() for row in rows} == {name}
    assert all(np.isfinite(float(row[3])) for row in rows)
    assert np.all(np.isfinite(flown[0].bound)) and len(flown[0].bound) == 10
    plot(flown, tmp_path / "localisers.png")
    assert (tmp_path / "localisers.png").stat().st_size > 10_000


def test_an_unknown_range_model_is_refused_with_the_known_ones():
    with pytest.raises(DcsimError, match="--ranges: unknown coloured; use white, biased, outliers"):
        range_cases(["white", "coloured"])
