"""One scenario seed, one independent generator per component."""

from __future__ import annotations

import numpy as np

from dcsim.run.seeding import component_rng
from dcsim.run.setup import setup_run


def test_same_seed_and_component_give_the_same_stream():
    assert np.array_equal(
        component_rng(3, "localiser").random(5), component_rng(3, "localiser").random(5)
    )


def test_components_and_seeds_get_different_streams():
    draws = {
        (seed, name): component_rng(seed, name).random(3).tobytes()
        for seed in (0, 1)
        for name in ("world", "localiser", "controller")
    }
    assert len(set(draws.values())) == len(draws)


def test_plugins_receive_their_role_generator():
    setup = setup_run(seed=11)
    for role, plugin in setup.plugins.items():
        assert np.array_equal(plugin.rng.random(4), component_rng(11, role).random(4))
    assert setup.scenario.world.seed == 11
    assert setup.plugin_versions()["controller"]["name"] == "pd"
