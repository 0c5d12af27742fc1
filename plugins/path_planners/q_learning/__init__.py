"""The ``q-learning`` planner (``planner.py``): its cell task (``cells.py``), tabular
training (``tabular_q.py``), its bench (``bench.py``) and the cell task as a Gymnasium
environment (``gym.py``)."""
