"""The machinery every message shares: frozen dataclasses with read-only array fields.

A message is a frozen dataclass deriving from :class:`Message`; its array fields are
declared with :func:`array_field`, converted to read-only float arrays and checked for
shape on construction. Two messages are equal when all their fields are (arrays
compared element-wise).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any, TypeVar, dataclass_transform

import numpy as np
from numpy.typing import ArrayLike

T = TypeVar("T")
M = TypeVar("M", bound="Message")
_NO_SHARED_DEFAULT = object()


def array_field(
    shape: tuple[int, ...] = (3,), default: ArrayLike | None = None, optional: bool = False
) -> Any:
    """Declare a message field holding a read-only float array.

    Parameters
    ----------
    shape : tuple of int
        Required shape; ``-1`` accepts any length along that axis.
    default : array_like, optional
        Default value; omit for a required field (give None, with ``optional``, for a
        field that is None unless given).
    optional : bool
        If true the field may be None (its default unless ``default`` is given), meaning
        "not given"; otherwise None is rejected.
    """
    if default is None:
        metadata = {"shape": shape, "optional": optional, "default": _NO_SHARED_DEFAULT}
        return field(default=None, metadata=metadata) if optional else field(metadata=metadata)
    shared = np.array(default, dtype=float)
    shared.setflags(write=False)
    metadata = {"shape": shape, "optional": optional, "default": shared}
    return field(default_factory=lambda: shared, metadata=metadata)


_ArrayField = tuple[str, tuple[int, ...], bool, bool, object]
_ARRAY_FIELDS: dict[type, tuple[_ArrayField, ...]] = {}


def _array_fields(cls: type) -> tuple[_ArrayField, ...]:
    """Name, shape, optionality, whether the shape is fully fixed (no ``-1``) and the
    shared read-only default of each array field of a message class (cached per class)."""
    found = _ARRAY_FIELDS.get(cls)
    if found is None:
        found = tuple(
            (
                f.name,
                f.metadata["shape"],
                f.metadata["optional"],
                -1 not in f.metadata["shape"],
                f.metadata["default"],
            )
            for f in fields(cls)
            if "shape" in f.metadata
        )
        _ARRAY_FIELDS[cls] = found
    return found


_FIELD_NAMES: dict[type, frozenset[str]] = {}


def _field_names(cls: type) -> frozenset[str]:
    """Names of every field of a message class (cached per class)."""
    names = _FIELD_NAMES.get(cls)
    if names is None:
        names = _FIELD_NAMES[cls] = frozenset(f.name for f in fields(cls))
    return names


def _shape_fits(shape: tuple[int, ...], wanted: tuple[int, ...]) -> bool:
    """Whether ``shape`` is ``wanted`` where ``-1`` in ``wanted`` accepts any length."""
    if len(shape) != len(wanted):
        return False
    for w, s in zip(wanted, shape, strict=True):
        if w != -1 and w != s:
            return False
    return True


def _owned_read_only(value: np.ndarray) -> bool:
    """Whether no one can write ``value``'s data: it is read-only and owns its data, or
    views a read-only array that does (as message fields and cached states are)."""
    if value.flags.writeable:
        return False
    base = value.base
    return base is None or (
        type(base) is np.ndarray and not base.flags.writeable and base.base is None
    )


_FLOAT = np.dtype(float)


class Message:
    """Base of every message: converts array fields and compares by value."""

    def __post_init__(self) -> None:
        values = self.__dict__
        for name, shape, optional, fixed, default in _array_fields(type(self)):
            raw = values[name]
            if raw is default or (raw is None and optional):
                continue  # a default is shared, read-only and of the right shape
            if (
                type(raw) is np.ndarray
                and raw.dtype == _FLOAT
                and (raw.shape == shape or not fixed and _shape_fits(raw.shape, shape))
                and _owned_read_only(raw)
            ):
                continue  # another message's field (or alike): kept, not copied
            value = np.array(raw, dtype=float)
            if value.shape != shape and (fixed or not _shape_fits(value.shape, shape)):
                raise ValueError(
                    f"{type(self).__name__}.{name} must have shape {shape}, got {value.shape}"
                )
            value.setflags(write=False)
            values[name] = value

    @classmethod
    def trusted(cls: type[M], **values: Any) -> M:
        """Build a message from values already in the form it keeps, without checks.

        For the framework's hot paths (a sensor's tracks, every tick): each field is
        given, arrays are read-only floats of the declared shapes that no one can
        write, and the class's own rules already hold. Anyone else calls the class.

        Raises
        ------
        TypeError
            If a field is missing or unknown.
        """
        names = _field_names(cls)
        if values.keys() != names:
            raise TypeError(f"{cls.__name__}.trusted needs exactly the fields {sorted(names)}")
        message = object.__new__(cls)
        message.__dict__.update(values)
        return message

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        for f in fields(self):  # type: ignore[arg-type]
            a, b = getattr(self, f.name), getattr(other, f.name)
            if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
                if a is None or b is None or not np.array_equal(a, b):
                    return False
            elif a != b:
                return False
        return True

    __hash__ = None  # type: ignore[assignment]


@dataclass_transform(frozen_default=True, eq_default=False, field_specifiers=(field, array_field))
def message(cls: type[T]) -> type[T]:
    """Class decorator making ``cls`` a frozen message dataclass."""
    return dataclass(frozen=True, eq=False)(cls)
