"""Campaign files: the schema of a campaign and its loading with precise errors.

A campaign file names a base scenario and says how its cases differ::

    name: default-dispersed
    scenario: ../default.yaml          # relative to this file
    seed: 2026                         # the campaign seed
    cases: 40                          # Monte Carlo draws
    set: {world.duration: 600.0}       # applied to every case
    grid: {controller.plugin: [pd, elastic]}
    dispersions:
      robot.initial.position: {type: normal, sigma: [2.0, 2.0, 1.0]}
      beacons.noise_sigma: {type: uniform, low: 0.02, high: 0.1}
    metrics: [delivered, delta_v_mps]

Keys of ``set``, ``grid`` and ``dispersions`` are key paths, the same as ``dcsim run
--set``. Problems are reported like a scenario's: file, line, key path, every problem
at once.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import Field, ValidationError, field_validator, model_validator

from dcsim.errors import CampaignError, Problem, ScenarioError
from dcsim.scenario.document import ScenarioDocument, parse_key_path, read_document_text
from dcsim.scenario.loader import schema_problems
from dcsim.scenario.model import MAX_SEED, Section

MAX_CASES = 1_000_000
"""Most cases in one campaign (Monte Carlo draws × grid points)."""

Numbers = float | list[float]
"""A scalar, or one value per axis of a vector key."""


class UniformDispersion(Section):
    """Uniform between ``low`` and ``high`` (scalars, or one per axis)."""

    type: Literal["uniform"]
    low: Numbers = Field(description="Least value (per axis for a vector key).")
    high: Numbers = Field(description="Largest value (per axis for a vector key).")


class NormalDispersion(Section):
    """Normal about ``mean`` (the base scenario's value if absent), optionally truncated."""

    type: Literal["normal"]
    mean: Numbers | None = Field(
        None, description="Mean; the base scenario's value at the key when absent."
    )
    sigma: Numbers = Field(description="Standard deviation (per axis for a vector key), ≥ 0.")
    low: Numbers | None = Field(None, description="Truncate below this value (per axis).")
    high: Numbers | None = Field(None, description="Truncate above this value (per axis).")

    @field_validator("sigma")
    @classmethod
    def _non_negative(cls, sigma: Numbers) -> Numbers:
        values = sigma if isinstance(sigma, list) else [sigma]
        if any(value < 0 for value in values):
            raise ValueError("a standard deviation is ≥ 0")
        return sigma


class ChoiceDispersion(Section):
    """One of ``values`` (any YAML values), with optional relative ``weights``."""

    type: Literal["choice"]
    values: list[Any] = Field(min_length=1, description="The values to choose from.")
    weights: list[Annotated[float, Field(ge=0)]] | None = Field(
        None, description="Relative weight of each value; equal when absent."
    )

    @model_validator(mode="after")
    def _weights_match(self) -> ChoiceDispersion:
        if self.weights is not None:
            if len(self.weights) != len(self.values):
                raise ValueError(
                    f"{len(self.weights)} weights for {len(self.values)} values: give one each"
                )
            if sum(self.weights) <= 0:
                raise ValueError("the weights sum to zero")
        return self


class SeedDispersion(Section):
    """The case's seed itself (an integer in 0 … 2³¹ − 1)."""

    type: Literal["seed"]


Dispersion = Annotated[
    UniformDispersion | NormalDispersion | ChoiceDispersion | SeedDispersion,
    Field(discriminator="type"),
]


class CampaignSpec(Section):
    """The validated content of a campaign file."""

    name: str = Field(min_length=1, description="The campaign's name.")
    description: str = Field("", description="What the campaign shows.")
    scenario: str = Field(
        min_length=1, description="The base scenario file, relative to the campaign file."
    )
    seed: int = Field(0, ge=0, le=MAX_SEED, description="The campaign seed.")
    cases: int = Field(
        1, ge=1, le=MAX_CASES, description="Monte Carlo draws (each run at every grid point)."
    )
    set: dict[str, Any] = Field(
        default_factory=dict, description="Key path → value applied to every case."
    )
    grid: dict[str, Annotated[list[Any], Field(min_length=1)]] = Field(
        default_factory=dict, description="Key path → values; every combination is run."
    )
    dispersions: dict[str, Dispersion] = Field(
        default_factory=dict, description="Key path → the distribution a case draws it from."
    )
    metrics: list[str] = Field(
        default_factory=list,
        description="Summary fields to collect and plot; every numeric one when empty.",
    )
    case_plots: bool = Field(False, description="Draw each case's plots in its run directory.")

    @property
    def grid_points(self) -> int:
        """Number of grid points (1 without a grid)."""
        count = 1
        for values in self.grid.values():
            count *= len(values)
        return count

    @property
    def total_cases(self) -> int:
        """Cases of the campaign: Monte Carlo draws × grid points."""
        return self.cases * self.grid_points


@dataclass(frozen=True)
class Campaign:
    """A loaded campaign: its validated file and its base scenario's document.

    Attributes
    ----------
    spec : CampaignSpec
        The campaign file's content.
    filename : str
        The campaign file as the user named it.
    text : str
        The campaign file's text (kept with the results, to resume and replay).
    base : ScenarioDocument
        The base scenario as parsed (no override applied).
    base_text : str
        The base scenario's text.
    """

    spec: CampaignSpec
    filename: str
    text: str
    base: ScenarioDocument
    base_text: str


def load_campaign(path: str | Path) -> Campaign:
    """Read and validate a campaign file and the base scenario it names.

    Raises
    ------
    CampaignError
        Listing every problem of the campaign file with its line and key path.
    ScenarioError
        If the base scenario cannot be read or parsed.
    """
    path = Path(path)
    try:
        text = read_document_text(path)
    except ScenarioError as error:
        raise CampaignError(str(path), error.problems) from None
    campaign = parse_campaign(text, str(path))
    base_path = path.parent / campaign.scenario
    try:
        base_text = read_document_text(base_path)
    except ScenarioError as error:
        message = f"cannot use the base scenario {base_path}: {error.problems[0].message}"
        raise CampaignError(str(path), [Problem("scenario", message)]) from None
    return Campaign(
        campaign, str(path), text, ScenarioDocument.from_text(base_text, str(base_path)), base_text
    )


def parse_campaign(text: str, filename: str) -> CampaignSpec:
    """Validate campaign ``text``.

    Raises
    ------
    CampaignError
        With one problem per invalid value, located by line and key path.
    """
    try:
        doc = ScenarioDocument.from_text(text, filename)
    except ScenarioError as error:
        raise CampaignError(filename, error.problems) from None
    try:
        spec = CampaignSpec.model_validate(doc.data)
    except ValidationError as error:
        raise CampaignError(filename, schema_problems(doc, error, CampaignSpec)) from None
    problems = _key_path_problems(doc, spec)
    if problems:
        raise CampaignError(filename, problems)
    return spec


def _key_path_problems(doc: ScenarioDocument, spec: CampaignSpec) -> list[Problem]:
    """Keys that are not key paths, and key paths named twice across sections."""
    problems = []
    owner: dict[tuple[str | int, ...], str] = {}
    for section in ("set", "grid", "dispersions"):
        for key in getattr(spec, section):
            try:
                path = parse_key_path(key)
            except ValueError as error:
                problems.append(doc.problem((section, key), str(error)))
                continue
            if path in owner:
                message = f"also in {owner[path]}: a key is set, swept or dispersed, not two"
                problems.append(doc.problem((section, key), message))
            owner.setdefault(path, section)
    return problems
