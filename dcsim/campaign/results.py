"""A campaign's results: one row per case, summary statistics, and pictures.

``results.csv`` and ``results.parquet`` hold one row per case: ``case``, ``draw``,
``seed``, the values it took (a vector split per axis: ``robot.initial.position[0]``),
``status``, ``reason``, the chosen summary metrics, ``case_wall_time_s`` and
``run_dir``. ``statistics.csv`` gives each metric's count, mean, standard deviation,
minimum, 5th percentile, median, 95th percentile and maximum over the cases that did
not fail (per grid point when there is a grid). ``plots/metrics.png`` shows each
metric's histogram and ``plots/scatter.png`` each metric against each dispersed value.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import yaml

from dcsim.campaign.cases import Case
from dcsim.campaign.spec import Campaign, NormalDispersion, UniformDispersion
from dcsim.errors import CampaignError, Problem
from dcsim.run.recording import column_name, column_unit
from dcsim.scenario import parse_key_path
from dcsim.scenario.loader import key_unit
from dcsim.scenario.model import frame_axes

if TYPE_CHECKING:
    import pandas

QUANTILES = {"p5": 0.05, "median": 0.5, "p95": 0.95}
"""The quantiles of ``statistics.csv``."""

WORLD_VECTOR_UNITS = ("m", "m/s", "rad/s")
"""Units of the scenario's vectors along the world's axes (positions, velocities, rates)."""

MAX_SCATTER_COLUMNS = 6
"""Dispersed values plotted against the metrics at most (the first ones)."""


def metric_names(campaign: Campaign, mission_type: str) -> list[str]:
    """The summary fields the campaign collects (every numeric one unless it names some).

    Raises
    ------
    CampaignError
        If a named metric is not a field of the mission's run summary.
    """
    from dcsim.missions import mission_class  # missions load the world engine
    from dcsim.run.loop import SUMMARY_FIGURES

    known = [*SUMMARY_FIGURES, *mission_class(mission_type).summary_names]
    named = campaign.spec.metrics
    unknown = [name for name in named if name not in known]
    if unknown:
        message = (
            f"{', '.join(unknown)}: not in the summary of a '{mission_type}' run "
            f"(its fields: {', '.join(known)})"
        )
        raise CampaignError(campaign.filename, [Problem("metrics", message)])
    return list(named) or known


def results_table(
    campaign: Campaign,
    cases: Sequence[Case],
    results: Mapping[int, Mapping[str, Any]],
    metrics: Sequence[str],
) -> pandas.DataFrame:
    """One row per case of ``cases``; a case without a result has status ``not run``."""
    import pandas

    rows = []
    for case in cases:
        result = results.get(case.index)
        summary = (result.get("summary") or {}) if result else {}
        row: dict[str, Any] = {"case": case.index, "draw": case.draw, "seed": case.seed}
        row.update(_value_columns(campaign, case.values))
        row["status"] = result["status"] if result else "not run"
        row["reason"] = result["reason"] if result else ""
        row.update({name: _number(summary.get(name)) for name in metrics})
        row["case_wall_time_s"] = _number(result.get("wall_time_s")) if result else np.nan
        row["run_dir"] = f"cases/{case.name}" if "sim_time_s" in summary else ""
        rows.append(row)
    return pandas.DataFrame(rows)


def statistics(table: pandas.DataFrame, metrics: Sequence[str], grid: Sequence[str]) -> Any:
    """Each metric's statistics over the cases that did not fail (per grid point)."""
    import pandas

    ran = table[table["status"].isin(["completed", "stopped"])]
    groups = ran.groupby(list(grid), sort=False) if grid else [((), ran)]
    rows = []
    for key, part in groups:
        point = dict(zip(grid, key if isinstance(key, tuple) else (key,), strict=True))
        for name in metrics:
            values = part[name].dropna().astype(float)
            row = {**point, "metric": name, "count": len(values)}
            if len(values):
                row.update(mean=values.mean(), std=values.std(ddof=1), min=values.min())
                row.update({q: values.quantile(f) for q, f in QUANTILES.items()})
                row["max"] = values.max()
            rows.append(row)
    return pandas.DataFrame(rows)


def write_results(
    directory: Path, campaign: Campaign, table: pandas.DataFrame, metrics: Sequence[str]
) -> pandas.DataFrame:
    """Write the results table, the statistics and the plots; return the statistics."""
    table.to_csv(directory / "results.csv", index=False)
    table.to_parquet(directory / "results.parquet", index=False)
    summary = statistics(table, metrics, list(campaign.spec.grid))
    summary.to_csv(directory / "statistics.csv", index=False)
    plot_results(directory / "plots", campaign, table, metrics)
    return summary


def plot_results(
    folder: Path, campaign: Campaign, table: pandas.DataFrame, metrics: Sequence[str]
) -> None:
    """Histograms of the metrics and their scatter against the dispersed values."""
    from dcsim.bench.figures import pyplot, save

    ran = table[table["status"].isin(["completed", "stopped"])]
    shown = [m for m in metrics if ran[m].notna().any()]
    if not shown:
        return
    folder.mkdir(exist_ok=True)
    plt = pyplot()
    groups = _grid_groups(ran, list(campaign.spec.grid))
    columns = min(3, len(shown))
    rows = -(-len(shown) // columns)
    figure, axes = plt.subplots(rows, columns, figsize=(4.5 * columns, 3.2 * rows), squeeze=False)
    for axis, name in zip(axes.flat, shown, strict=False):
        for label, part in groups:
            axis.hist(part[name].dropna().astype(float), bins=20, alpha=0.6, label=label)
        axis.set(xlabel=axis_label(campaign, name), ylabel="cases")
        axis.grid(alpha=0.3)
    for axis in axes.flat[len(shown) :]:
        axis.set_visible(False)
    _legend(axes.flat[0], groups)
    figure.suptitle(f"{campaign.spec.name}: {len(ran)} cases")
    save(figure, folder / "metrics.png")
    dispersed = _dispersed_columns(campaign, ran)[:MAX_SCATTER_COLUMNS]
    if dispersed:
        _scatter(folder / "scatter.png", campaign, groups, shown, dispersed)


def _scatter(
    path: Path,
    campaign: Campaign,
    groups: list[tuple[str, Any]],
    metrics: Sequence[str],
    dispersed: Sequence[str],
) -> None:
    from dcsim.bench.figures import pyplot, save

    plt = pyplot()
    figure, axes = plt.subplots(
        len(metrics),
        len(dispersed),
        figsize=(3.2 * len(dispersed), 2.6 * len(metrics)),
        squeeze=False,
        sharex="col",
    )
    for row, name in enumerate(metrics):
        for column, value in enumerate(dispersed):
            axis = axes[row, column]
            for label, part in groups:
                axis.scatter(part[value], part[name], s=10, alpha=0.7, label=label)
            axis.grid(alpha=0.3)
            if column == 0:
                axis.set_ylabel(axis_label(campaign, name))
            if row == len(metrics) - 1:
                axis.set_xlabel(axis_label(campaign, value))
    _legend(axes[0, 0], groups)
    figure.suptitle(f"{campaign.spec.name}: metrics against the dispersed values")
    save(figure, path)


def axis_label(campaign: Campaign, column: str) -> str:
    """A results column as an axis label: its name in words and its unit.

    A summary metric's unit is its name's suffix (``delta_v_mps`` → ``delta v [m/s]``);
    a dispersed key's is the scenario schema's, and an index into a 3-vector is named
    after the base scenario's frame (``robot.initial.position[0]`` → ``robot initial
    position, radial [m]`` in LVLH).
    """
    if column.split("[")[0] not in campaign.spec.dispersions:
        unit = column_unit(column)
        return column_name(column).replace("_", " ") + (f" [{unit}]" if unit else "")
    path = parse_key_path(column)
    key, index = (path[:-1], path[-1]) if isinstance(path[-1], int) else (path, None)
    words = " ".join(str(part).replace("_", " ") for part in key)
    unit = key_unit(campaign.base.data, key)
    if index is not None and unit in WORLD_VECTOR_UNITS:
        world = campaign.base.data.get("world")
        frame = world.get("frame", "lvlh") if isinstance(world, dict) else "lvlh"
        words += f", {frame_axes(frame)[index]}"
    elif index is not None:
        words += f" [{index}]"
    return words + (f" [{unit}]" if unit else "")


def _grid_groups(table: Any, grid: list[str]) -> list[tuple[str, Any]]:
    """(label, rows) per grid point; one unlabelled group without a grid."""
    if not grid:
        return [("", table)]
    grouped = table.groupby(grid, sort=False)
    return [
        (", ".join(f"{k}={v}" for k, v in zip(grid, key, strict=True)), part)
        for key, part in grouped
    ]


def _legend(axis: Any, groups: list[tuple[str, Any]]) -> None:
    """A legend of the grid points, when there is more than one."""
    if len(groups) > 1:
        axis.legend(fontsize="small")


def _dispersed_columns(campaign: Campaign, table: Any) -> list[str]:
    """The table's numeric columns that hold dispersed values."""
    return [
        column
        for column in table.columns
        if column.split("[")[0] in campaign.spec.dispersions
        and np.issubdtype(table[column].dtype, np.number)
        and table[column].nunique() > 1
    ]


def _value_columns(campaign: Campaign, values: Mapping[str, Any]) -> dict[str, Any]:
    """A case's values as table cells: drawn vectors per axis, other data as YAML."""
    cells: dict[str, Any] = {}
    for path, value in values.items():
        drawn = isinstance(
            campaign.spec.dispersions.get(path), UniformDispersion | NormalDispersion
        )
        if drawn and isinstance(value, list):
            cells.update({f"{path}[{axis}]": x for axis, x in enumerate(value)})
        elif isinstance(value, bool | int | float | str) or value is None:
            cells[path] = value
        else:
            cells[path] = yaml.safe_dump(value, default_flow_style=True).strip()
    return cells


def _number(value: Any) -> float:
    """A summary value as a float cell (NaN when absent or not a number)."""
    if isinstance(value, bool | int | float):
        return float(value)
    return np.nan
