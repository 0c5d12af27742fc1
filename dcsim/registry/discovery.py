"""The plugin registry: finds plugin classes through entry points and checks them.

Plugins are found through the ``dcsim`` entry-point group; dcsim's own built-ins use the
same group. Each entry point names either a module implementing the
:func:`~dcsim.registry.hookspecs.dcsim_plugin_classes` hook or a plugin class itself.

The environment variable ``DCSIM_LOAD_PLUGINS`` (a comma-separated list of distribution
names) restricts which external packages are loaded; dcsim's built-ins always are.
Set it to an empty string to load only the built-ins.
"""

from __future__ import annotations

import importlib.metadata as md
import inspect
import os
import re
import warnings
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np
import pluggy

from dcsim.errors import (
    DuplicatePluginError,
    PluginInterfaceError,
    PluginLoadWarning,
    PluginNotFoundError,
    did_you_mean,
)
from dcsim.params import PluginParams
from dcsim.registry import hookspecs
from dcsim.registry.interfaces import PLUGIN_KINDS, Plugin

LOAD_PLUGINS_ENV = "DCSIM_LOAD_PLUGINS"
"""Environment variable restricting which external plugin distributions load."""

BUILTIN_DISTRIBUTION = "dcsim"
_NAME_PATTERN = re.compile(r"^[a-z][a-z0-9_-]*$")


@dataclass(frozen=True)
class PluginOrigin:
    """Where a plugin came from.

    Attributes
    ----------
    distribution : str
        Name of the installed distribution that provides it.
    version : str
        That distribution's version.
    entry_point : str
        The entry point (``name = value``) or module it was registered from.
    """

    distribution: str
    version: str
    entry_point: str

    def __str__(self) -> str:
        return f"{self.distribution} {self.version} ({self.entry_point})"


@dataclass(frozen=True)
class RegisteredPlugin:
    """A plugin class accepted by the registry.

    Attributes
    ----------
    cls : type of Plugin
        The plugin class.
    origin : PluginOrigin
        Where it came from.
    """

    cls: type[Plugin]
    origin: PluginOrigin

    @property
    def kind(self) -> str:
        """The plugin kind, e.g. ``"controller"``."""
        return self.cls.kind

    @property
    def name(self) -> str:
        """The plugin's name."""
        return self.cls.name

    def as_dict(self) -> dict[str, str]:
        """The listing of ``dcsim plugins --json``: kind, name, summary, origin."""
        return {
            "kind": self.kind,
            "name": self.name,
            "summary": self.cls.summary,
            "distribution": self.origin.distribution,
            "version": self.origin.version,
            "entry_point": self.origin.entry_point,
        }


def check_plugin_class(obj: Any) -> type[Plugin]:
    """Check that ``obj`` is a complete plugin class and return it.

    Raises
    ------
    PluginInterfaceError
        Saying what is missing: the base class, ``name``, ``summary``, ``Params`` or an
        abstract method of the kind's interface.
    """
    kinds = ", ".join(c.__name__ for c in PLUGIN_KINDS.values())
    label = getattr(obj, "__qualname__", repr(obj))
    if not inspect.isclass(obj) or not issubclass(obj, tuple(PLUGIN_KINDS.values())):
        raise PluginInterfaceError(f"{label} is not a plugin class: derive it from one of {kinds}")
    name = obj.__dict__.get("name", getattr(obj, "name", None))
    if not isinstance(name, str) or not _NAME_PATTERN.match(name):
        raise PluginInterfaceError(
            f"{label} must set `name` to a lower-case identifier such as 'my-planner', got {name!r}"
        )
    summary = getattr(obj, "summary", None)
    if not isinstance(summary, str) or not summary.strip() or "\n" in summary.strip():
        raise PluginInterfaceError(f"plugin '{name}' ({label}) must set `summary` to one line")
    params = getattr(obj, "Params", None)
    if not (inspect.isclass(params) and issubclass(params, PluginParams)):
        raise PluginInterfaceError(
            f"plugin '{name}' ({label}): `Params` must be a subclass of dcsim.api.PluginParams"
        )
    missing = sorted(getattr(obj, "__abstractmethods__", ()))
    if missing:
        methods = ", ".join(f"{m}()" for m in missing)
        raise PluginInterfaceError(
            f"plugin '{name}' ({label}) does not implement {methods} of the {obj.kind} interface"
        )
    return obj


def _normalise(distribution: str) -> str:
    return re.sub(r"[-_.]+", "-", distribution).lower()


class PluginRegistry:
    """All plugin classes known to this process, by kind and name.

    Use :meth:`discover` to build the registry from installed packages; tests and
    scripts can add modules or classes by hand with :meth:`register_module` and
    :meth:`register_class`.

    Attributes
    ----------
    warnings : list of str
        Problems met while loading (packages that failed to import, rejected classes,
        duplicate names); each was also issued as a :class:`PluginLoadWarning`.
    """

    def __init__(self) -> None:
        self._manager = pluggy.PluginManager(hookspecs.PROJECT_NAME)
        self._manager.add_hookspecs(hookspecs)
        self._plugins: dict[tuple[str, str], list[RegisteredPlugin]] = {}
        self.warnings: list[str] = []

    @classmethod
    def discover(cls, group: str = hookspecs.PROJECT_NAME) -> PluginRegistry:
        """Build a registry from the installed entry points of ``group``.

        A package that fails to import, or provides a broken class, is reported as a
        :class:`PluginLoadWarning`; every other plugin still loads.
        """
        registry = cls()
        allowed = os.environ.get(LOAD_PLUGINS_ENV)
        allowed_names = (
            None if allowed is None else {_normalise(n) for n in allowed.split(",") if n.strip()}
        )
        entry_points = sorted(
            md.entry_points(group=group), key=lambda e: (e.dist.name if e.dist else "", e.name)
        )
        for ep in entry_points:
            dist = ep.dist.name if ep.dist else "unknown"
            external = _normalise(dist) != BUILTIN_DISTRIBUTION
            if external and allowed_names is not None and _normalise(dist) not in allowed_names:
                continue
            version = ep.dist.version if ep.dist else "unknown"
            origin = PluginOrigin(dist, version, f"{ep.name} = {ep.value}")
            try:
                loaded = ep.load()
            except Exception as exc:  # any import failure of a third-party package
                registry._warn(
                    f"plugin package {dist} (entry point '{ep.name}' = {ep.value}) failed to "
                    f"load and was skipped: {type(exc).__name__}: {exc}"
                )
                continue
            registry.register(loaded, origin)
        return registry

    def register(self, obj: ModuleType | type[Plugin], origin: PluginOrigin) -> None:
        """Register a hook module or a plugin class, warning instead of raising."""
        try:
            if inspect.isclass(obj):
                self.register_class(obj, origin)
            else:
                self.register_module(obj, origin)
        except PluginInterfaceError as exc:
            self._warn(f"{exc}; it comes from {origin} and was skipped")
        except Exception as exc:  # a third party's hook raised
            self._warn(
                f"plugin package {origin} failed while registering its plugins and was "
                f"skipped: {type(exc).__name__}: {exc}"
            )

    def register_module(self, module: ModuleType, origin: PluginOrigin) -> None:
        """Register the classes returned by ``module``'s ``dcsim_plugin_classes`` hook."""
        self._manager.register(module, name=origin.entry_point)
        for impl in self._manager.hook.dcsim_plugin_classes.get_hookimpls():
            if impl.plugin is module:
                for plugin_cls in impl.function() or ():
                    self.register_class(plugin_cls, origin)

    def register_class(self, plugin_cls: type[Plugin], origin: PluginOrigin) -> None:
        """Check and register one plugin class.

        Raises
        ------
        PluginInterfaceError
            If the class does not satisfy its kind's interface.
        """
        check_plugin_class(plugin_cls)
        key = (plugin_cls.kind, plugin_cls.name)
        entries = self._plugins.setdefault(key, [])
        entries.append(RegisteredPlugin(plugin_cls, origin))
        if len(entries) == 2:
            self._warn(self._duplicate_message(key))

    def _duplicate_message(self, key: tuple[str, str]) -> str:
        origins = " and ".join(str(p.origin) for p in self._plugins[key])
        return (
            f"two plugins register the {key[0]} name '{key[1]}': {origins}; uninstall one, "
            f"or choose one with {LOAD_PLUGINS_ENV}"
        )

    def _warn(self, message: str) -> None:
        self.warnings.append(message)
        warnings.warn(message, PluginLoadWarning, stacklevel=3)

    @property
    def hook(self) -> pluggy.HookRelay:
        """The pluggy hook relay: ``registry.hook.dcsim_run_event(run=..., event=...)``."""
        return self._manager.hook

    def plugins(self, kind: str | None = None) -> list[RegisteredPlugin]:
        """All registered plugins (of ``kind``, if given), ordered by kind then name."""
        order = list(PLUGIN_KINDS)
        found = [p for entries in self._plugins.values() for p in entries]
        if kind is not None:
            self._check_kind(kind)
            found = [p for p in found if p.kind == kind]
        return sorted(found, key=lambda p: (order.index(p.kind), p.name, p.origin.distribution))

    def names(self, kind: str) -> list[str]:
        """Names of the registered plugins of ``kind``, sorted."""
        return sorted({p.name for p in self.plugins(kind)})

    def get(self, kind: str, name: str) -> RegisteredPlugin:
        """Look up the plugin ``name`` of ``kind``.

        Raises
        ------
        PluginNotFoundError
            Listing the available names and the closest match.
        DuplicatePluginError
            If two packages registered the name, naming both.
        """
        self._check_kind(kind)
        entries = self._plugins.get((kind, name))
        if not entries:
            available = self.names(kind)
            listing = ", ".join(available) or "none installed"
            raise PluginNotFoundError(
                f"no {kind} plugin named '{name}' (available: {listing})"
                + did_you_mean(name, available)
            )
        if len(entries) > 1:
            raise DuplicatePluginError(self._duplicate_message((kind, name)))
        return entries[0]

    def create(
        self,
        kind: str,
        name: str,
        params: PluginParams | Mapping[str, Any] | None = None,
        rng: np.random.Generator | None = None,
    ) -> Plugin:
        """Instantiate plugin ``name`` of ``kind`` with validated ``params`` and ``rng``."""
        return self.get(kind, name).cls(params, rng)

    @staticmethod
    def _check_kind(kind: str) -> None:
        if kind not in PLUGIN_KINDS:
            raise PluginNotFoundError(
                f"unknown plugin kind '{kind}' (kinds: {', '.join(PLUGIN_KINDS)})"
            )

    def __iter__(self) -> Iterator[RegisteredPlugin]:
        return iter(self.plugins())
