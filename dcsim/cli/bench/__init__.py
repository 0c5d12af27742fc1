"""``dcsim bench``: measure dcsim and its plugins against references.

Every bench prints its results as Markdown for docs/benchmarks.md on stdout and its
progress on stderr. The benches of dcsim's engine are in :mod:`~dcsim.cli.bench.engine`,
those of the built-in localisers, task planners, controllers and tracker, and the
capture's, in :mod:`~dcsim.cli.bench.algorithms`, those of the path planners in
:mod:`~dcsim.cli.bench.path_planners`. Plugin packages add their own benches
(``dcsim bench ant-colony``) through the ``dcsim_register_commands`` hook
(:mod:`dcsim.cli.plugin_commands`).
"""

from __future__ import annotations

import click

from dcsim.cli.bench import algorithms, engine, path_planners
from dcsim.cli.plugin_commands import PluginGroup


@click.group(
    "bench", cls=PluginGroup, short_help="Measure dcsim and its plugins against references."
)
def bench_group() -> None:
    """Measure dcsim and its plugins; results go into docs/benchmarks.md."""


bench_group.add_command(engine.bench_world_command)
bench_group.add_command(engine.bench_dynamics_command)
bench_group.add_command(engine.bench_soak_command)
bench_group.add_command(engine.bench_fmu_command)
bench_group.add_command(engine.bench_campaign_command)
bench_group.add_command(engine.bench_peers_command)
bench_group.add_command(engine.bench_manipulator_command)
bench_group.add_command(engine.bench_gym_command)
bench_group.add_command(algorithms.bench_localisers_command)
bench_group.add_command(algorithms.bench_task_planners_command)
bench_group.add_command(algorithms.bench_controllers_command)
bench_group.add_command(algorithms.bench_tracking_command)
bench_group.add_command(algorithms.bench_capture_command)
bench_group.add_command(path_planners.bench_grid_search_command)
bench_group.add_command(path_planners.bench_path_planners_command)
