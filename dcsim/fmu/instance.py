"""FMI 2.0 co-simulation FMUs read and driven through fmpy, by variable name."""

from __future__ import annotations

import shutil
from collections.abc import Iterable, Mapping
from ctypes import byref
from pathlib import Path
from typing import Any

from dcsim.errors import DcsimError
from dcsim.fmu.native import release_interpreter_state

_STATUS = ("OK", "WARNING", "DISCARD", "ERROR", "FATAL", "PENDING")
_TYPES = {"Real": float, "Integer": int, "Boolean": bool, "Enumeration": int}


class FmuError(DcsimError):
    """An FMU cannot be used as asked: a file that is not an FMI 2.0 co-simulation FMU, a
    variable it does not have or not of the kind needed, two FMUs that do not fit, or a
    call the FMU refused."""


class FmuCallError(FmuError):
    """An FMI call returned an error status.

    Attributes
    ----------
    function : str
        The FMI function, e.g. ``fmi2DoStep``.
    status : int
        Its status: 2 discard, 3 error, 4 fatal.
    messages : list of (str, str)
        What the FMU logged during the call.
    """

    def __init__(self, path: Path, function: str, status: int, messages: list) -> None:
        label = _STATUS[status] if 0 <= status < len(_STATUS) else str(status)
        said = "; ".join(message for _, message in messages) or "no message"
        super().__init__(f"{path.name}: {function} returned {label}: {said}")
        self.function, self.status, self.messages = function, status, messages


def _a(word: str) -> str:
    """``word`` with its indefinite article."""
    return f"{'an' if word[0] in 'aeiou' else 'a'} {word}"


class FmuDescription:
    """The model description of an FMI 2.0 co-simulation FMU, for checking variables.

    Parameters
    ----------
    path : str or Path
        The ``.fmu`` file.

    Attributes
    ----------
    path : Path
        The FMU file.
    model : fmpy.model_description.ModelDescription
        The parsed description.
    variables : dict of str to fmpy ScalarVariable
        Its variables by name.

    Raises
    ------
    FmuError
        If there is no such file, or it is not an FMI 2.0 FMU with co-simulation.
    """

    def __init__(self, path: str | Path) -> None:
        from fmpy import read_model_description

        self.path = Path(path)
        if not self.path.is_file():
            raise FmuError(f"no FMU file at {self.path}")
        try:
            self.model = read_model_description(str(self.path))
        except Exception as error:  # fmpy raises plain exceptions for broken files
            raise FmuError(f"{self.path} is not a readable FMU: {error}") from error
        if self.model.fmiVersion != "2.0" or self.model.coSimulation is None:
            raise FmuError(f"{self.path} is not an FMI 2.0 co-simulation FMU")
        self.variables = {v.name: v for v in self.model.modelVariables}

    def variable(self, name: str, causality: Iterable[str] = (), types: Iterable[str] = ()) -> Any:
        """The variable ``name``, checked to have one of ``causality`` and ``types``.

        Parameters
        ----------
        name : str
            Variable name.
        causality : iterable of str
            Allowed causalities (``input``, ``output``, ``parameter``...); any if empty.
        types : iterable of str
            Allowed FMI types (``Real``, ``Integer``, ``Boolean``...); any if empty.

        Raises
        ------
        FmuError
            If there is no such variable, or its causality or type is not allowed.
        """
        found = self.variables.get(name)
        if found is None:
            known = ", ".join(sorted(self.variables)) or "none"
            raise FmuError(f"{self.path.name} has no variable {name!r} (it has: {known})")
        allowed, kinds = tuple(causality), tuple(types)
        if allowed and found.causality not in allowed:
            raise FmuError(
                f"{self.path.name}: {name!r} is {_a(found.causality)}, "
                f"not {' or '.join(_a(c) for c in allowed)}"
            )
        if kinds and found.type not in kinds:
            raise FmuError(
                f"{self.path.name}: {name!r} is of type {found.type}, not {' or '.join(kinds)}"
            )
        return found

    def names(self, causality: str) -> list[str]:
        """Names of the variables of one causality (``input``, ``output``, ``parameter``)."""
        return [n for n, v in self.variables.items() if v.causality == causality]


class FmuInstance:
    """An FMI 2.0 co-simulation FMU, instantiated and stepped by variable name.

    The FMU's log messages are kept in :attr:`messages`; a failed FMI call raises
    ``fmpy.fmi1.FMICallException`` (its ``status`` says which).

    Parameters
    ----------
    path : str or Path
        The ``.fmu`` file.
    instance_name : str
        Name of the instance (appears in the FMU's log).

    Attributes
    ----------
    path : Path
        The FMU file.
    description : FmuDescription
        Its model description.
    messages : list of (str, str)
        ``(status, message)`` of every log message the FMU sent.

    Raises
    ------
    FmuError
        If the file is not an FMI 2.0 FMU with a co-simulation interface.
    """

    def __init__(self, path: str | Path, instance_name: str = "dcsim") -> None:
        from fmpy import extract
        from fmpy.fmi2 import FMU2Slave

        self.description = FmuDescription(path)
        self.path = self.description.path
        self.messages: list[tuple[str, str]] = []
        self._unzipped = extract(str(self.path))
        self._callbacks = self._logging_callbacks()
        self._instantiated = False
        try:
            self._fmu = FMU2Slave(
                guid=self.description.model.guid,
                unzipDirectory=self._unzipped,
                modelIdentifier=self.description.model.coSimulation.modelIdentifier,
                instanceName=instance_name,
            )
            self._fmu.instantiate(callbacks=self._callbacks, loggingOn=True)
        except Exception as error:  # fmpy raises bare exceptions; the log says why
            shutil.rmtree(self._unzipped, ignore_errors=True)
            said = "; ".join(message for _, message in self.messages) or str(error)
            raise FmuError(f"{self.path.name} cannot be instantiated: {said}") from error
        self._instantiated = True
        self._plans: dict[
            tuple[str, tuple[str, ...]], list[tuple[Any, list[int], list[str], type]]
        ] = {}

    def _logging_callbacks(self) -> Any:
        from fmpy import calloc, free
        from fmpy.fmi2 import (
            fmi2CallbackAllocateMemoryTYPE,
            fmi2CallbackFreeMemoryTYPE,
            fmi2CallbackFunctions,
            fmi2CallbackLoggerTYPE,
        )
        from fmpy.logging import addLoggerProxy

        def log(component: Any, instance: bytes, status: int, category: bytes, message: bytes):
            label = _STATUS[status] if 0 <= status < len(_STATUS) else str(status)
            self.messages.append((label, message.decode("utf-8", "replace")))

        callbacks = fmi2CallbackFunctions()
        callbacks.logger = fmi2CallbackLoggerTYPE(log)
        callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        addLoggerProxy(byref(callbacks))
        return callbacks

    # ------------------------------------------------------------------ variables
    def set(self, values: Mapping[str, float | int | bool]) -> None:
        """Set inputs and parameters by name (each value converted to its FMI type).

        Raises
        ------
        FmuError
            If a name is not an input or a parameter of the FMU.
        FmuCallError
            If the FMU refuses the values.
        """
        for setter, refs, group, kind in self._plan("set", tuple(values)):
            self._call(setter, refs, [kind(values[name]) for name in group])

    def get(self, names: Iterable[str]) -> dict[str, float | int | bool]:
        """Values of variables by name, in the order asked.

        Raises
        ------
        FmuError
            If the FMU has no variable of a name.
        """
        names = tuple(names)
        out: dict[str, float | int | bool] = {}
        for getter, refs, group, _ in self._plan("get", names):
            out.update(zip(group, getter(refs), strict=True))
        return {name: out[name] for name in names}

    def _plan(
        self, action: str, names: tuple[str, ...]
    ) -> list[tuple[Any, list[int], list[str], type]]:
        """Per FMI type: fmpy's method, the value references, the names and the Python type.

        Built once per ``action`` and set of names (a simulation asks the same every
        step); setting checks that each name is an input or a parameter.
        """
        key = (action, names)
        if key not in self._plans:
            causality = ("input", "parameter") if action == "set" else ()
            by_type: dict[str, list[str]] = {}
            for name in names:
                by_type.setdefault(self.description.variable(name, causality).type, []).append(name)
            self._plans[key] = [
                (
                    self._method(action, kind),
                    [self.description.variables[n].valueReference for n in group],
                    group,
                    _TYPES[kind],
                )
                for kind, group in by_type.items()
            ]
        return self._plans[key]

    def _method(self, action: str, kind: str) -> Any:
        """fmpy's ``getReal``, ``setInteger``... for an FMI type (enumerations as Integer)."""
        return getattr(self._fmu, f"{action}{kind if kind in ('Real', 'Boolean') else 'Integer'}")

    # ------------------------------------------------------------------ lifecycle
    def initialise(
        self, start_time: float = 0.0, start_values: Mapping[str, float | int | bool] | None = None
    ) -> None:
        """Set up the experiment at ``start_time``, set start values, initialise.

        Raises
        ------
        FmuCallError
            If the FMU refuses a step of it.
        """
        self._call(self._fmu.setupExperiment, startTime=start_time)
        self._call(self._fmu.enterInitializationMode)
        self.set(start_values or {})
        self._call(self._fmu.exitInitializationMode)

    def step(self, time: float, step_size: float) -> None:
        """One ``fmi2DoStep`` from ``time`` over ``step_size`` seconds.

        Raises
        ------
        FmuCallError
            If the FMU refuses the step (``status`` 2, discard: it did not advance).
        """
        self._call(
            self._fmu.doStep, currentCommunicationPoint=time, communicationStepSize=step_size
        )

    def terminate(self) -> None:
        """``fmi2Terminate``."""
        self._call(self._fmu.terminate)

    def reset(self) -> None:
        """``fmi2Reset``: back to the state after instantiation."""
        self._call(self._fmu.reset)

    def _call(self, function: Any, *args: Any, **kwargs: Any) -> None:
        """Call an fmpy method; turn a failed status into :class:`FmuCallError`."""
        from fmpy.fmi1 import FMICallException

        logged = len(self.messages)
        try:
            function(*args, **kwargs)
        except FMICallException as error:
            raise FmuCallError(
                self.path, error.function, error.status, self.messages[logged:]
            ) from None

    def close(self) -> None:
        """Free the instance and delete the unzipped FMU."""
        if self._instantiated:
            self._instantiated = False
            release_interpreter_state(self._fmu.dll)  # a pythonfmu FMU's: see dcsim.fmu.native
            self._fmu.freeInstance()
            shutil.rmtree(self._unzipped, ignore_errors=True)

    def __enter__(self) -> FmuInstance:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
