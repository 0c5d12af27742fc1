"""The plugin registry: finds plugins through entry points and imports them when used.

A plugin is declared by an entry point in its kind's group (``dcsim.localisers``,
``dcsim.task_planners``, ``dcsim.path_planners``, ``dcsim.controllers``) whose name is the
plugin's name and whose value is a module implementing the
:func:`~dcsim.registry.hookspecs.dcsim_plugin_classes` hook (or the plugin class itself).
The registry knows such a plugin's kind, name and distribution from the metadata alone
and imports its module only when the plugin is looked up (a run, a bench, ``dcsim plugins
NAME``); dcsim's built-ins are declared this way.

Entry points of the ``dcsim`` group itself, the form the registry has always read, name
a module whose plugins' kinds and names the metadata does not give, and which may
observe runs or add commands without providing any plugin: those modules are imported
when the registry is built, as they always were.

The environment variable ``DCSIM_LOAD_PLUGINS`` (a comma-separated list of distribution
names) restricts which external packages are seen; dcsim's built-ins always are.
Set it to an empty string to see only the built-ins.
"""

from __future__ import annotations

import importlib.metadata as md
import inspect
import os
import re
import warnings
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from types import ModuleType
from typing import Any, cast

import numpy as np
import pluggy

from dcsim.errors import (
    DuplicatePluginError,
    PluginInterfaceError,
    PluginLoadError,
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


def kind_group(kind: str, base: str = hookspecs.PROJECT_NAME) -> str:
    """The entry-point group that declares plugins of ``kind``.

    Parameters
    ----------
    kind : str
        A plugin kind, e.g. ``"controller"``.
    base : str
        The group the kinds' groups are named after.

    Returns
    -------
    str
        ``"dcsim.controllers"`` for ``"controller"``: the base, a dot, the kind in plural.
    """
    return f"{base}.{kind}s"


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
class PluginEntry:
    """A plugin as its entry point declares it, known without importing its module.

    Attributes
    ----------
    kind : str
        The plugin kind, from the entry point's group.
    name : str
        The plugin's name, the entry point's name.
    origin : PluginOrigin
        Where it comes from.
    """

    kind: str
    name: str
    origin: PluginOrigin

    def as_dict(self) -> dict[str, str]:
        """The listing of ``dcsim plugins --json``: kind, name and origin."""
        return {
            "kind": self.kind,
            "name": self.name,
            "distribution": self.origin.distribution,
            "version": self.origin.version,
            "entry_point": self.origin.entry_point,
        }


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

    @property
    def entry(self) -> PluginEntry:
        """The plugin's kind, name and origin."""
        return PluginEntry(self.kind, self.name, self.origin)

    def as_dict(self) -> dict[str, str]:
        """Kind, name, summary and origin (``dcsim plugins NAME --json``)."""
        return {**self.entry.as_dict(), "summary": self.cls.summary}


@dataclass
class _Declared:
    """A plugin declared in a kind's group, and what importing it gave (once tried)."""

    entry: PluginEntry
    entry_point: md.EntryPoint
    error: PluginLoadError | PluginInterfaceError | None = None
    tried: bool = False


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
    plugin_cls = cast("type[Plugin]", obj)
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
            f"plugin '{name}' ({label}) does not implement {methods} of the "
            f"{plugin_cls.kind} interface"
        )
    return plugin_cls


def _order(kind: str, name: str, origin: PluginOrigin) -> tuple[int, str, str]:
    """The listing order: kind in data-flow order, then name, then distribution."""
    return list(PLUGIN_KINDS).index(kind), name, origin.distribution


def _normalise(distribution: str) -> str:
    return re.sub(r"[-_.]+", "-", distribution).lower()


def _origin(ep: md.EntryPoint) -> PluginOrigin:
    dist = ep.dist
    return PluginOrigin(
        dist.name if dist else "unknown",
        dist.version if dist else "unknown",
        f"{ep.name} = {ep.value}",
    )


def _installed(group: str) -> list[md.EntryPoint]:
    """The entry points of ``group`` that ``DCSIM_LOAD_PLUGINS`` lets through, in order
    of distribution, then name."""
    allowed = os.environ.get(LOAD_PLUGINS_ENV)
    names = None if allowed is None else {_normalise(n) for n in allowed.split(",") if n.strip()}

    def wanted(ep: md.EntryPoint) -> bool:
        dist = _normalise(ep.dist.name if ep.dist else "unknown")
        return dist == BUILTIN_DISTRIBUTION or names is None or dist in names

    found = [ep for ep in md.entry_points(group=group) if wanted(ep)]
    return sorted(found, key=lambda ep: (ep.dist.name if ep.dist else "", ep.name))


class PluginRegistry:
    """All plugins known to this process, by kind and name.

    Use :meth:`discover` to build the registry from installed packages; tests and
    scripts can add modules or classes by hand with :meth:`register_module` and
    :meth:`register_class`. A plugin declared in its kind's entry-point group is
    imported the first time :meth:`get`, :meth:`find`, :meth:`create` or
    :meth:`plugins` needs it; :meth:`entries` and :meth:`names` read the metadata only.

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
        self._declared: dict[tuple[str, str], list[_Declared]] = {}
        self.warnings: list[str] = []

    @classmethod
    def discover(cls, group: str = hookspecs.PROJECT_NAME) -> PluginRegistry:
        """Build a registry from the installed entry points.

        The kinds' groups (:func:`kind_group`) are read as metadata; nothing of them is
        imported. The modules of ``group`` itself are imported now: a package that fails
        to import, or provides a broken class, is reported as a
        :class:`PluginLoadWarning`, and every other plugin still loads.
        """
        registry = cls()
        for kind in PLUGIN_KINDS:
            for ep in _installed(kind_group(kind, group)):
                registry.declare(PluginEntry(kind, ep.name, _origin(ep)), ep)
        for ep in _installed(group):
            origin = _origin(ep)
            try:
                loaded = ep.load()
            except Exception as exc:  # any import failure of a third-party package
                registry._warn(
                    f"plugin package {origin.distribution} (entry point '{origin.entry_point}') "
                    f"failed to load and was skipped: {type(exc).__name__}: {exc}"
                )
                continue
            registry.register(loaded, origin)
        return registry

    def declare(self, entry: PluginEntry, entry_point: md.EntryPoint) -> None:
        """Add a plugin known from its metadata; ``entry_point`` is loaded when it is used.

        Raises
        ------
        PluginNotFoundError
            If ``entry.kind`` is not a plugin kind.
        """
        self._check_kind(entry.kind)
        self._declared.setdefault((entry.kind, entry.name), []).append(
            _Declared(entry, entry_point)
        )

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
        """Register ``module``'s hooks and the classes its ``dcsim_plugin_classes`` returns."""
        self._manager.register(module, name=origin.entry_point)
        for plugin_cls in self._hook_classes(module):
            self.register_class(plugin_cls, origin)

    def _hook_classes(self, module: ModuleType) -> list[Any]:
        """What the ``dcsim_plugin_classes`` hook of ``module`` (registered) returns."""
        found: list[Any] = []
        for impl in self._manager.hook.dcsim_plugin_classes.get_hookimpls():
            if impl.plugin is module:
                given: Any = impl.function()  # what a third party returned
                found.extend(given or ())
        return found

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

    def _load(self, declared: _Declared) -> None:
        """Import a declared plugin's module and register its class, once; a failure is
        kept in ``declared.error``."""
        if declared.tried:
            return
        declared.tried = True
        entry = declared.entry
        label = f"{entry.kind} plugin '{entry.name}' of {entry.origin}"
        try:
            loaded = declared.entry_point.load()
        except Exception as exc:  # any import failure of a third-party package
            declared.error = PluginLoadError(
                f"{label} failed to import: {type(exc).__name__}: {exc}; fix or uninstall "
                f"{entry.origin.distribution}, or leave it out with {LOAD_PLUGINS_ENV}"
            )
            return
        try:
            self._register_declared(entry, loaded)
        except PluginInterfaceError as exc:
            declared.error = PluginInterfaceError(f"{exc}; it comes from {entry.origin}")
        except Exception as exc:  # a third party's hook raised
            declared.error = PluginLoadError(
                f"{label} failed while giving its classes: {type(exc).__name__}: {exc}"
            )

    def _register_declared(self, entry: PluginEntry, loaded: Any) -> None:
        """Register the class of ``entry`` from what its entry point loaded (a module, whose
        hooks are registered once, or the class), unless the ``dcsim`` group gave it."""
        if inspect.isclass(loaded):
            candidates = [loaded]
        else:
            if not self._manager.is_registered(loaded):
                self._manager.register(loaded, name=entry.origin.entry_point)
            candidates = self._hook_classes(loaded)
        plugin_cls = self._declared_class(entry, candidates)
        if all(p.cls is not plugin_cls for p in self._plugins.get((entry.kind, entry.name), ())):
            self.register_class(plugin_cls, entry.origin)

    @staticmethod
    def _declared_class(entry: PluginEntry, candidates: Iterable[Any]) -> type[Plugin]:
        """The class among ``candidates`` that is the plugin ``entry`` declares.

        Raises
        ------
        PluginInterfaceError
            If none is, or it is incomplete.
        """
        for obj in candidates:
            declares = (getattr(obj, "kind", None), getattr(obj, "name", None))
            if inspect.isclass(obj) and declares == (entry.kind, entry.name):
                return check_plugin_class(obj)
        raise PluginInterfaceError(
            f"entry point '{entry.origin.entry_point}' of {entry.origin.distribution} in "
            f"{kind_group(entry.kind)} declares the {entry.kind} plugin '{entry.name}', but "
            f"its module gives no {entry.kind} class with name = '{entry.name}'"
        )

    def _load_declared(self, kind: str | None, name: str | None, strict: bool) -> None:
        """Load the declared plugins of ``kind`` and ``name`` (every one for None).

        Raises
        ------
        PluginLoadError, PluginInterfaceError
            If ``strict`` and one of them failed; otherwise failures are warnings.
        """
        for (k, n), declared_list in self._declared.items():
            if (kind is None or k == kind) and (name is None or n == name):
                for declared in declared_list:
                    first = not declared.tried
                    self._load(declared)
                    if declared.error is not None and strict:
                        raise declared.error
                    if declared.error is not None and first:
                        self._warn(f"{declared.error}; it was skipped")

    def load_all(self) -> None:
        """Import every declared plugin: a failure is a warning, the others still load."""
        self._load_declared(None, None, strict=False)

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
        """The pluggy hook relay: ``registry.hook.dcsim_run_event(run=..., event=...)``.

        Its implementations are those of the modules imported so far: the ``dcsim``
        group's and those of the plugins that were looked up (a run's own).
        """
        return self._manager.hook

    def entries(self, kind: str | None = None) -> list[PluginEntry]:
        """Every plugin (of ``kind``, if given) by kind, name and origin, without importing
        any declared plugin; ordered by kind, name, then distribution."""
        if kind is not None:
            self._check_kind(kind)
        loaded = [p.entry for ps in self._plugins.values() for p in ps]
        seen = {(e.kind, e.name, e.origin.distribution) for e in loaded}
        declared = [
            d.entry
            for ds in self._declared.values()
            for d in ds
            if not d.tried and (d.entry.kind, d.entry.name, d.entry.origin.distribution) not in seen
        ]
        found = [e for e in (*declared, *loaded) if kind in (None, e.kind)]
        return sorted(found, key=lambda e: _order(e.kind, e.name, e.origin))

    def plugins(self, kind: str | None = None) -> list[RegisteredPlugin]:
        """All plugins (of ``kind``, if given), ordered by kind then name.

        Imports every declared plugin of ``kind``; one that fails is a warning and is
        left out.
        """
        if kind is not None:
            self._check_kind(kind)
        self._load_declared(kind, None, strict=False)
        return self._registered(kind, None)

    def _registered(self, kind: str | None, name: str | None) -> list[RegisteredPlugin]:
        """The registered plugins of ``kind`` and ``name`` (any for None), in order."""
        found = [
            p
            for ps in self._plugins.values()
            for p in ps
            if kind in (None, p.kind) and name in (None, p.name)
        ]
        return sorted(found, key=lambda p: _order(p.kind, p.name, p.origin))

    def names(self, kind: str) -> list[str]:
        """Names of the plugins of ``kind``, sorted (from metadata: nothing is imported)."""
        return sorted({e.name for e in self.entries(kind)})

    def find(self, name: str, kind: str | None = None) -> list[RegisteredPlugin]:
        """The plugins called ``name`` (of ``kind``, if given), importing only those.

        Raises
        ------
        PluginLoadError, PluginInterfaceError
            If one of them fails to import or does not give its class.
        """
        if kind is not None:
            self._check_kind(kind)
        self._load_declared(kind, name, strict=True)
        return self._registered(kind, name)

    def get(self, kind: str, name: str) -> RegisteredPlugin:
        """Look up the plugin ``name`` of ``kind``, importing it if it is not yet.

        Raises
        ------
        PluginNotFoundError
            Listing the available names and the closest match.
        DuplicatePluginError
            If two packages registered the name, naming both.
        PluginLoadError, PluginInterfaceError
            If its module fails to import or does not give the class it declares,
            naming the plugin and its distribution.
        """
        self._check_kind(kind)
        self._load_declared(kind, name, strict=True)
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
