"""A campaign's cases: seeds by index, dispersed values, and the overrides that make them.

Case ``i`` is Monte Carlo draw ``k = i // G`` at grid point ``g = i % G`` (``G`` grid
points; draw-major, so the first cases cover every grid point). Draw ``k``'s seed
sequence is ``SeedSequence(campaign_seed).spawn(cases)[k]``, built from the index
alone, so the same campaign gives the same cases on any cluster and ``--cases N``
gives the first ``N`` of them. Every grid point sees the same draws (common random
numbers: a sweep compares settings on identical dispersions).

A case is the base scenario with ``--set`` overrides applied in this order: the
campaign's ``set``, the grid point, ``world.seed`` = the case seed (unless the
campaign sets, sweeps or disperses ``world.seed`` itself) and the dispersions. Each
dispersion draws from its own generator (keyed by its key path), so adding one never
changes another's values.
"""

from __future__ import annotations

import copy
import itertools
import zlib
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import yaml
from scipy.stats import truncnorm

from dcsim.campaign.spec import (
    Campaign,
    ChoiceDispersion,
    Dispersion,
    NormalDispersion,
    SeedDispersion,
    UniformDispersion,
)
from dcsim.errors import CampaignError, Problem, ScenarioError
from dcsim.registry.discovery import PluginRegistry
from dcsim.scenario import ScenarioDocument, dump_scenario, parse_key_path, read_scenario
from dcsim.scenario.model import MAX_SEED

SEED_KEY = "world.seed"
"""The key path a case's seed goes to unless the campaign names it."""

MAX_REPORTED = 5
"""Invalid cases described one by one before the rest are counted."""


@dataclass(frozen=True)
class Case:
    """One case of a campaign.

    Attributes
    ----------
    index : int
        The case's index (0-based).
    draw : int
        Its Monte Carlo draw.
    seed : int
        Its seed (0 … 2³¹ − 1).
    values : dict of str to object
        Key path → the value the case takes: its grid point, then its dispersions.
    overrides : tuple of str
        The ``key.path=value`` overrides that make the case from the base scenario,
        in the order applied (``dcsim run BASE --set ...`` repeats it).
    """

    index: int
    draw: int
    seed: int
    values: dict[str, Any]
    overrides: tuple[str, ...]

    @property
    def name(self) -> str:
        """The case's folder name, ``case-000017``."""
        return f"case-{self.index:06d}"


def draw_seed_sequence(campaign_seed: int, draw: int) -> np.random.SeedSequence:
    """Draw ``draw``'s seed sequence: ``SeedSequence(campaign_seed).spawn(n)[draw]``."""
    return np.random.SeedSequence(campaign_seed, spawn_key=(draw,))


def draw_seed(campaign_seed: int, draw: int) -> int:
    """The seed of Monte Carlo draw ``draw`` (0 … 2³¹ − 1)."""
    state = draw_seed_sequence(campaign_seed, draw).generate_state(1, np.uint32)[0]
    return int(state) & MAX_SEED


def override_text(path: str, value: Any) -> str:
    """The ``--set`` text assigning ``value`` (plain data) to ``path``; it reads back equal."""
    text = yaml.safe_dump(value, default_flow_style=True, width=2**31)
    end_of_document = "\n...\n"  # PyYAML ends a lone scalar with it
    return f"{path}={text.removesuffix(end_of_document).strip()}"


def campaign_cases(
    campaign: Campaign, registry: PluginRegistry, count: int | None = None
) -> list[Case]:
    """The campaign's cases (the first ``count`` of them), each checked as a scenario.

    Raises
    ------
    CampaignError
        If a dispersion names no key of the base scenario or does not fit its value,
        or a case is not a valid scenario (the first few such cases are described).
    """
    spec = campaign.spec
    total = spec.total_cases if count is None else min(count, spec.total_cases)
    fixed = tuple(override_text(path, value) for path, value in spec.set.items())
    nominal = _resolved_data(campaign, fixed, registry)
    _check_dispersions(campaign, nominal)
    points = list(itertools.product(*spec.grid.values()))
    seed_named = any(parse_key_path(p) == ("world", "seed") for p in _named_paths(campaign))
    cases = []
    for index in range(total):
        draw, point = divmod(index, len(points))
        seed = draw_seed(spec.seed, draw)
        values = dict(zip(spec.grid, points[point], strict=True))
        for path, dispersion in spec.dispersions.items():
            values[path] = draw_value(dispersion, _lookup(nominal, path), spec.seed, draw, path)
        chosen = [] if seed_named else [override_text(SEED_KEY, seed)]
        chosen += [override_text(path, value) for path, value in values.items()]
        cases.append(Case(index, draw, seed, values, (*fixed, *chosen)))
    _check_cases(campaign, cases, registry)
    return cases


def case_document(base: ScenarioDocument, case: Case) -> ScenarioDocument:
    """The base scenario's document with ``case``'s overrides applied (``base`` untouched)."""
    document = copy.deepcopy(base)
    for assignment in case.overrides:
        document.apply_override(assignment)
    return document


def draw_value(
    dispersion: Dispersion, nominal: Any, campaign_seed: int, draw: int, path: str
) -> Any:
    """The value draw ``draw`` takes for the dispersion at ``path`` (plain data).

    ``nominal`` is the base scenario's value at ``path`` (a normal dispersion's mean
    when it gives none; a vector key's length).
    """
    if isinstance(dispersion, SeedDispersion):
        return draw_seed(campaign_seed, draw)
    key = (draw, zlib.crc32(path.encode()))  # a child of the draw's sequence, named by path
    rng = np.random.default_rng(np.random.SeedSequence(campaign_seed, spawn_key=key))
    if isinstance(dispersion, ChoiceDispersion):
        weights = None if dispersion.weights is None else np.asarray(dispersion.weights)
        chosen = rng.choice(
            len(dispersion.values), p=None if weights is None else weights / weights.sum()
        )
        return copy.deepcopy(dispersion.values[int(chosen)])
    if isinstance(dispersion, UniformDispersion):
        low, high = np.broadcast_arrays(*_shaped(nominal, dispersion.low, dispersion.high))
        return _plain(rng.uniform(low, high))
    return _plain(_normal(dispersion, nominal, rng))


def _normal(dispersion: NormalDispersion, nominal: Any, rng: np.random.Generator) -> np.ndarray:
    """A normal draw, truncated to [low, high] where given; ``sigma = 0`` gives the mean."""
    centre = nominal if dispersion.mean is None else dispersion.mean
    lowest = -np.inf if dispersion.low is None else dispersion.low
    highest = np.inf if dispersion.high is None else dispersion.high
    mean, sigma, low, high = np.broadcast_arrays(
        *_shaped(nominal, centre, dispersion.sigma, lowest, highest)
    )
    scale = np.where(sigma > 0, sigma, 1.0)
    value = truncnorm.rvs(
        (low - mean) / scale, (high - mean) / scale, mean, scale, random_state=rng
    )
    return np.where(sigma > 0, value, mean)


def _shaped(nominal: Any, *parts: Any) -> list[np.ndarray]:
    """The parameters as float arrays, scalars spread over a vector key's axes."""
    arrays = [np.asarray(part, dtype=float) for part in parts]
    if isinstance(nominal, list):
        arrays = [np.broadcast_to(a, (len(nominal),)) if a.ndim == 0 else a for a in arrays]
    return arrays


def _plain(value: float | np.ndarray) -> float | list[float]:
    """A draw as YAML-ready data: a float, or a list of floats."""
    value = np.asarray(value)
    return float(value) if value.ndim == 0 else [float(x) for x in value]


def _named_paths(campaign: Campaign) -> list[str]:
    spec = campaign.spec
    return [*spec.set, *spec.grid, *spec.dispersions]


def _resolved_data(
    campaign: Campaign, fixed: Sequence[str], registry: PluginRegistry
) -> dict[str, Any]:
    """The base scenario with the campaign's ``set`` applied, resolved, as plain data."""
    try:
        document = copy.deepcopy(campaign.base)
        for assignment in fixed:
            document.apply_override(assignment)
        scenario = read_scenario(document, registry=registry)
    except ScenarioError as error:
        raise CampaignError(
            campaign.filename,
            [Problem("set", f"the base scenario with these values is invalid: {error}")],
        ) from None
    return yaml.safe_load(dump_scenario(scenario))


_MISSING = object()


def _lookup(data: Any, path: str) -> Any:
    """The value at key path ``path`` in resolved scenario data, or ``_MISSING``."""
    for key in parse_key_path(path):
        if isinstance(key, int):
            if not isinstance(data, list) or key >= len(data):
                return _MISSING
        elif not isinstance(data, dict) or key not in data:
            return _MISSING
        data = data[key]
    return data


def _check_dispersions(campaign: Campaign, nominal: dict[str, Any]) -> None:
    """Every dispersion names a key of the base scenario and fits its value's shape."""
    problems = []
    for path, dispersion in campaign.spec.dispersions.items():
        value = _lookup(nominal, path)
        message = _dispersion_problem(dispersion, value, campaign.base.filename)
        if message:
            problems.append(_located(campaign, ("dispersions", path), message))
    if problems:
        raise CampaignError(campaign.filename, problems)


def _dispersion_problem(dispersion: Dispersion, value: Any, base: str) -> str:
    """Why ``dispersion`` cannot disperse ``value`` (the base's value at its key), or ''."""
    if value is _MISSING:
        return f"names no key of the scenario {base} (use the paths of dcsim run --set)"
    if isinstance(dispersion, ChoiceDispersion | SeedDispersion):
        return ""
    if isinstance(dispersion, NormalDispersion) and dispersion.mean is None:
        numeric = isinstance(value, int | float) or (
            isinstance(value, list) and all(isinstance(x, int | float) for x in value)
        )
        if not numeric:
            return f"the base value {value!r} is not a number or a vector: give a mean"
    parts = [getattr(dispersion, key, None) for key in ("low", "high", "mean", "sigma")]
    lengths = {len(p) for p in parts if isinstance(p, list)}
    if isinstance(value, list):
        lengths.add(len(value))
    if len(lengths) > 1:
        return f"vectors of different lengths {sorted(lengths)}: give one value per axis"
    low, high = getattr(dispersion, "low", None), getattr(dispersion, "high", None)
    if low is not None and high is not None and np.any(np.asarray(low) > np.asarray(high)):
        return "low is above high"
    return ""


def _check_cases(campaign: Campaign, cases: Sequence[Case], registry: PluginRegistry) -> None:
    """Each case is a valid scenario; the first few invalid ones are described."""
    problems = []
    invalid = 0
    for case in cases:
        try:
            document = case_document(campaign.base, case)
            read_scenario(document, registry=registry)
        except ScenarioError as error:
            invalid += 1
            if invalid <= MAX_REPORTED:
                found = "; ".join(p.describe(error.filename) for p in error.problems)
                problems.append(Problem(f"case {case.index}", f"invalid scenario: {found}"))
    if invalid > MAX_REPORTED:
        problems.append(Problem("", f"and {invalid - MAX_REPORTED} more invalid cases"))
    if problems:
        raise CampaignError(campaign.filename, problems)


def _located(campaign: Campaign, path: tuple[str, ...], message: str) -> Problem:
    """A problem at ``path`` of the campaign file, with its line."""
    document = ScenarioDocument.from_text(campaign.text, campaign.filename)
    return document.problem(path, message)
