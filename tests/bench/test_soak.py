"""``dcsim bench soak``: samples, verdicts and repeated FMU lifetimes."""

from __future__ import annotations

import mmap

import pytest

from dcsim.bench.soak import SoakResult, SoakSample, resident_bytes


def test_verdicts_compare_the_right_parts_of_the_run():
    samples = [
        SoakSample(tick, 100_000_000 + 1000 * tick, 1e-3 * (2.0 if tick > 900 else 1.0))
        for tick in range(100, 1001, 100)
    ]
    result = SoakResult(samples)
    assert result.memory_growth == pytest.approx(900_000 / 100_100_000)
    assert result.tick_time(0.1, 0.2) == 1e-3 and result.tick_time(0.9, 1.0) == 2e-3
    assert result.tick_time_change == pytest.approx(1.0)


def test_resident_memory_is_read_from_the_process():
    # A fresh anonymous mapping: none of its pages is resident until touched (a
    # bytearray may reuse memory the process freed but still holds).
    with mmap.mmap(-1, 50 * 2**20) as ballast:
        before = resident_bytes()
        for page in range(0, len(ballast), mmap.PAGESIZE):  # touch every page
            ballast[page] = 1
        assert resident_bytes() - before > 40 * 2**20


def test_bench_soak_prints_samples_verdicts_and_fmu_cycles(dcsim_cli, tmp_path):
    plot = tmp_path / "soak.png"
    result = dcsim_cli(
        "bench", "soak", "--ticks", "300", "--samples", "10", "--fmu-cycles", "3",
        "--out", str(tmp_path / "run"), "--plot", str(plot),
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "| tick | resident memory (MB) | time per tick (µs) |" in result.stdout
    assert "| 300 |" in result.stdout
    assert "resident memory growth from 10 % to 100 % of the run:" in result.stdout
    assert "FMU: 3 cycles, resident memory" in result.stdout
    assert plot.stat().st_size > 10_000
    assert (tmp_path / "run" / "telemetry.csv").read_text().count("\n") == 302
