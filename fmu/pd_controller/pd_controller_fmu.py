"""An external PD position controller as an FMI 2.0 co-simulation slave (pythonfmu).

It depends on numpy and pythonfmu only, not on dcsim: it stands for a controller made
in another tool. Build it with::

    pythonfmu build -f fmu/pd_controller/pd_controller_fmu.py -d build/

and fly it in dcsim with the ``fmu`` controller plugin (see docs/fmu.md).

The law is that of dcsim's ``pd`` controller, gains in closed form: the double
integrator's poles placed at those of ``s² + 2ζω s + ω²`` give ``kp = ω²``,
``kd = 2ζω``, and

    v_cmd = v_ref + (kp / kd) (p_ref − p),   |v_cmd| ≤ speed_limit
    F = m (kd (v_cmd − v) + a_ref),          |F| ≤ max_force

Each step computes the force from the inputs set at its start; the force is the
output after the step, to be held over it.
"""

from __future__ import annotations

import ctypes

import numpy as np
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.enums import Fmi2Initial

# pythonfmu 0.7 runs this file again at every instantiation and then releases a reference
# to the module's namespace it does not own; add one reference per run that nothing ever
# releases, so the namespace is never freed under the FMU. (Held in a Python list, they
# would be released again when the interpreter clears modules at exit: once per
# instantiation more than the namespace was referenced.)
ctypes.pythonapi.Py_IncRef(ctypes.py_object(globals()))

AXES = ("x", "y", "z")
VECTOR_INPUTS = (
    "position",
    "velocity",
    "reference.position",
    "reference.velocity",
    "reference.acceleration",
)
SCALAR_INPUTS = {"mass": 100.0, "max_force": 5.0, "speed_limit": 0.5}


def clip_norm(vector: np.ndarray, largest: float) -> np.ndarray:
    """``vector`` scaled down along itself so its norm is at most ``largest``."""
    norm = float(np.linalg.norm(vector))
    return vector * (largest / norm) if norm > largest else vector


class PDControllerFmu(Fmi2Slave):
    """Speed- and force-limited PD position control of a free flyer (force out)."""

    author = "dcsim example"
    description = "PD position controller with speed and force limits (external FMU example)"

    def __init__(self, **kwargs) -> None:
        super().__init__(**kwargs)
        self.bandwidth = 0.2  # rad/s
        self.damping = 0.9
        self.u = {f"{name}.{axis}": 0.0 for name in VECTOR_INPUTS for axis in AXES}
        self.u.update(SCALAR_INPUTS)
        self.force = np.zeros(3)
        for name, description in (
            ("bandwidth", "Natural frequency of the closed position loop, rad/s."),
            ("damping", "Damping ratio of the closed position loop."),
        ):
            self.register_variable(
                Real(
                    name,
                    causality=Fmi2Causality.parameter,
                    variability=Fmi2Variability.fixed,
                    description=description,
                )
            )
        for name in self.u:
            self.register_variable(
                Real(
                    name,
                    causality=Fmi2Causality.input,
                    getter=lambda n=name: self.u[n],
                    setter=lambda value, n=name: self.u.__setitem__(n, value),
                )
            )
        for index, axis in enumerate(AXES):
            self.register_variable(
                Real(
                    f"force.{axis}",
                    causality=Fmi2Causality.output,
                    initial=Fmi2Initial.exact,
                    description="Commanded thrust, N.",
                    getter=lambda i=index: float(self.force[i]),
                )
            )

    def _vector(self, name: str) -> np.ndarray:
        return np.array([self.u[f"{name}.{axis}"] for axis in AXES])

    def do_step(self, current_time: float, step_size: float) -> bool:
        """Compute the force for the coming step from the current inputs."""
        kp, kd = self.bandwidth**2, 2.0 * self.damping * self.bandwidth
        error = self._vector("reference.position") - self._vector("position")
        v_cmd = clip_norm(
            self._vector("reference.velocity") + (kp / kd) * error, self.u["speed_limit"]
        )
        acceleration = kd * (v_cmd - self._vector("velocity")) + self._vector(
            "reference.acceleration"
        )
        self.force = clip_norm(self.u["mass"] * acceleration, self.u["max_force"])
        return True
