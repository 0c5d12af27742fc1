"""The debris mission's references are whole messages: built without checks on the hot
path, they hold what the constructor would and nothing anyone can write."""

from __future__ import annotations

import numpy as np

from dcsim.messages import Reference
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run


def test_every_reference_is_what_the_constructor_would_build():
    runner = Runner(setup_run(None, ["world.duration=260"]), keep_rows=False)
    runner.open()
    modes = set()
    while not runner.ended:
        reference = runner.reference
        assert type(reference) is Reference and Reference(**vars(reference)) == reference
        for value in vars(reference).values():
            assert not isinstance(value, np.ndarray) or not value.flags.writeable
        modes.add(runner.mode)
        runner.advance()
    runner.close()
    assert {"MOVE_TO_NEXT", "MOVE_TO_DROP"} <= modes  # its attitude and its drop speed added
    assert runner.reference.attitude is not None and runner.reference.max_speed < np.inf
