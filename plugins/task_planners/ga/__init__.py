"""The ``ga`` task planner (``planner.py``): a request as arrays with the leg-time search
(``problem.py``) and the individuals with their genetic operators (``population.py``)."""
