"""`dcsim bench fmu` measures both ways over the same ticks."""

from __future__ import annotations

from dcsim.bench.fmu import bench_fmu, markdown_table


def test_bench_fmu_times_the_same_ticks_natively_and_through_the_fmu():
    lines = []
    result = bench_fmu(None, duration=3.0, repeats=2, progress=lines.append)
    assert result.ticks == 30  # 3 s at the 0.1 s control period
    assert len(result.native) == len(result.fmu) == 2 and len(lines) == 2
    assert all(t > 0 for t in result.native + result.fmu)
    assert "FMU overhead" in markdown_table(result)
