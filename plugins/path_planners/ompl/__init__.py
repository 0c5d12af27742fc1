"""The OMPL planners: ``ompl-control`` (kinodynamic, ``control.py``, with its rigid-body
model and closing manoeuvres) and ``ompl-geometric`` (``geometric.py``), and what they
share (``support.py``: OMPL's seed, the worker process per plan)."""
