"""A run: its set-up, the closed loop, the recording, and runs from Python.

``setup`` resolves a scenario and constructs one plugin per role; ``loop`` runs the
closed loop (the :class:`~dcsim.run.loop.Runner`); ``recording`` writes telemetry,
events and the summary; ``directory`` prepares the run directory; ``seeding`` gives
each component its generator; ``scripting`` is what :mod:`dcsim.api` offers a script
(load a scenario, run it, step it, read a run back).
"""
