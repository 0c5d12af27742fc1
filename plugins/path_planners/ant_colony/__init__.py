"""The ``ant-colony`` planner (``planner.py``): its candidate graph of cross-sections
(``layered_graph.py``), its ants (``colony.py``) and its bench (``bench.py``)."""
