"""What a run shows afterwards: figures, shape outlines, the run viewer, generated docs.

``plots`` draws a run's figures, ``outlines`` the objects' shapes in them, ``viewer`` the
interactive 3-D page of a run, and ``docgen`` keeps the generated blocks of the
documentation in step with the code.
"""
