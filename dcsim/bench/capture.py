"""``dcsim bench capture``: the capture of a tumbling target over a dispersed campaign.

The cases of a campaign of the ``capture`` mission (by default
``scenarios/campaigns/debris_capture_dispersed.yaml``: the target's tumble rate and
axis and the collector's start dispersed) run on the campaign engine
(:mod:`dcsim.campaign`), and each case is judged against the capture's targets: a
success is a case that captured the target and detumbled the stack to the mission's
``detumbled_rate_deg_s``, with no contact force above the gripper's ``force_limit``,
the base turned at most ``max_base_excursion_deg`` from its attitude at the standoff,
and no link of the arm other than the gripper's, nor the base, striking the target.
Every other case is a failure, with each of its causes: the mission's reason for
stopping (no approach path, no path for the arm, a grip that did not hold, a run that
failed), a detumble not reached, a force or a turn above its limit, the arm striking
the target.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from dcsim.bench.figures import pyplot, save
from dcsim.campaign import Campaign, Case
from dcsim.campaign.cases import case_document
from dcsim.errors import DcsimError
from dcsim.missions.capture.settings import CaptureMissionSection
from dcsim.scenario import validate
from dcsim.scenario.model import ManipulatorSection, Scenario

if TYPE_CHECKING:
    import pandas

DEFAULT_CAMPAIGN = "debris_capture_dispersed.yaml"
"""The bench's campaign: a file of the checkout's ``scenarios/campaigns``."""
TARGET_SUCCESSES = 0.95
"""The share of cases that must succeed (at least 95 of 100)."""


@dataclass(frozen=True)
class Limits:
    """What a successful capture keeps within, from the campaign's base scenario.

    Attributes
    ----------
    rate_deg_s : float
        The stack's angular rate a detumble must reach (``detumbled_rate_deg_s``), deg/s.
    force_N : float
        The gripper's contact force limit (``robot.gripper.force_limit``), N.
    turn_deg : float
        The base's largest turn from its attitude at the standoff
        (``max_base_excursion_deg``), deg.
    """

    rate_deg_s: float
    force_N: float
    turn_deg: float

    @classmethod
    def of(cls, scenario: Scenario) -> Limits:
        """The limits of a capture scenario.

        Raises
        ------
        DcsimError
            If the scenario is not a capture by a manipulator with a gripper.
        """
        mission, robot = scenario.mission, scenario.robot
        if not isinstance(mission, CaptureMissionSection):
            raise DcsimError(
                f"dcsim bench capture judges captures; the campaign's scenario is a "
                f"'{mission.type}' mission: name a campaign of a capture scenario"
            )
        assert isinstance(robot, ManipulatorSection) and robot.gripper is not None  # its rules
        return cls(
            mission.detumbled_rate_deg_s,
            robot.gripper.force_limit,
            mission.max_base_excursion_deg,
        )

    def definition(self) -> str:
        """What a success is, in words."""
        return (
            f"captured and detumbled to <= {self.rate_deg_s:g} deg/s, no contact force "
            f"above the gripper's {self.force_N:g} N, the base turned <= "
            f"{self.turn_deg:g} deg and no arm link or the base striking the target"
        )


@dataclass(frozen=True)
class CaptureCase:
    """One judged case.

    Attributes
    ----------
    index : int
        The case's index in the campaign.
    spin_deg_s : tuple of float
        The target's initial angular velocity, body axes, deg/s.
    start_offset_m : tuple of float
        The collector's start from the base scenario's, world frame, m.
    figures : dict of str to float
        The summary's ``peak_contact_force_N``, ``max_base_turn_deg``,
        ``detumble_time_s``, ``latch_time_s``, ``contact_time_s`` and
        ``final_target_rate_deg_s`` (NaN where the run has none).
    faults : tuple of str
        Why the case is not a success (empty for a success).
    """

    index: int
    spin_deg_s: tuple[float, float, float]
    start_offset_m: tuple[float, float, float]
    figures: dict[str, float]
    faults: tuple[str, ...]

    @property
    def success(self) -> bool:
        """Whether the case met every limit."""
        return not self.faults

    @property
    def rate_deg_s(self) -> float:
        """The target's initial tumble rate, deg/s."""
        return float(np.linalg.norm(self.spin_deg_s))

    @property
    def axis_lean_deg(self) -> float:
        """The angle between the target's initial spin axis and its body x axis, deg."""
        spin = np.array(self.spin_deg_s)
        return float(np.degrees(math.atan2(float(np.linalg.norm(spin[1:])), spin[0])))


FIGURES = (
    ("peak_contact_force_N", "peak contact force [N]", "cases that touched the target"),
    ("max_base_turn_deg", "base turn from the standoff [deg]", "cases that touched the target"),
    ("detumble_time_s", "detumble time, latch to still [s]", "detumbled cases"),
    ("latch_time_s", "capture (latch) time from the start [s]", "captured cases"),
)
"""The figures summarised: summary field, label, and the cases it is taken over (a run
has a force and a turn even when it never touched; the times only when they happened)."""
TOUCHED = FIGURES[0][2]
"""The cases the force and the turn are taken over."""


def judge(
    campaign: Campaign, cases: Sequence[Case], table: pandas.DataFrame, limits: Limits
) -> list[CaptureCase]:
    """Judge every case of a capture campaign's results table against its limits.

    Parameters
    ----------
    campaign : Campaign
        The campaign (its base scenario gives the nominal start).
    cases : sequence of Case
        The cases run, in index order.
    table : pandas.DataFrame
        The campaign's results (one row per case, with the capture's summary fields).
    limits : Limits
        What a success keeps within (:func:`limits_of` the campaign).

    Returns
    -------
    list of CaptureCase
        One per case, in index order.
    """
    base = validate(campaign.base)
    rows = {int(row["case"]): row for row in table.to_dict("records")}
    start = np.array(base.robot.initial.position)
    judged = []
    for case in cases:
        scenario = validate(case_document(campaign.base, case))
        row = rows[case.index]
        assert isinstance(scenario.mission, CaptureMissionSection)  # as the base's
        target = scenario.mission.target
        figures = {name: _number(row.get(name)) for name in _FIELDS}
        judged.append(
            CaptureCase(
                case.index,
                _triple(target.angular_velocity_deg_s),
                _triple(np.array(scenario.robot.initial.position) - start),
                figures,
                tuple(_faults(row, figures, limits)),
            )
        )
    return judged


_FIELDS = (
    *(name for name, _, _ in FIGURES),
    "contact_time_s",
    "final_target_rate_deg_s",
    "arm_links_struck",
)


def _faults(row: dict[str, Any], figures: dict[str, float], limits: Limits) -> Iterable[str]:
    """Why a case is not a success, in the order of the capture's steps."""
    if row["status"] in ("failed", "not run"):
        yield f"{row['status']}: {row.get('reason') or 'no reason given'}"
        return
    if not _true(row.get("captured")):
        yield f"not captured: {row.get('reason') or 'no reason given'}"
    elif not _true(row.get("detumbled")):
        yield (
            f"not detumbled to {limits.rate_deg_s:g} deg/s "
            f"(target at {figures['final_target_rate_deg_s']:.2f} deg/s): {row.get('reason')}"
        )
    if figures["peak_contact_force_N"] > limits.force_N:
        yield f"contact force above the gripper's {limits.force_N:g} N"
    if figures["max_base_turn_deg"] > limits.turn_deg:
        yield f"base turned more than {limits.turn_deg:g} deg"
    if _true(row.get("arm_links_struck")):
        yield f"the arm struck the target ({_number(row['arm_links_struck']):.0f} links)"


_NUMBER = re.compile(r"(?<![\w.])-?\d+(?:\.\d+)?(?:e[-+]?\d+)?(?!\w|\.\d)", re.IGNORECASE)
"""A number in a fault's reason: an integer, a decimal or scientific notation."""


def cause(fault: str) -> str:
    """A fault without its brackets, and the reason it quotes without its numbers, so
    that like faults group together.

    ``no path: near a singularity (9x, last det(J Jᵀ) 1.68e-09)`` gives
    ``no path: near a singularity``; ``not captured: no approach path: the straight path
    passes 6.33 m from obstacle 1`` gives ``not captured: no approach path: the straight
    path passes … m from obstacle …``. The bench's own words before the first colon
    keep their numbers (the limits: the same in every case).
    """
    while (shorter := re.sub(r"\s*\([^()]*\)", "", fault)) != fault:
        fault = shorter  # innermost brackets first: they nest, as in det(J Jᵀ)
    head, colon, reason = fault.partition(": ")
    return (head + colon + _NUMBER.sub("…", reason)).strip()


def markdown(judged: Sequence[CaptureCase], limits: Limits) -> str:
    """The success rate, the figures' median / 95th percentile / max, the failures grouped
    by cause, and each failed case's dispersed values, as Markdown."""
    return "\n\n".join(
        (
            verdict(judged, limits),
            figures_table(judged),
            causes_table(judged),
            failures_table(judged),
        )
    )


def verdict(judged: Sequence[CaptureCase], limits: Limits) -> str:
    """``Success: 96 of 100 cases (96 %); target at least 95 %: met.`` and the definition."""
    count = len(judged)
    successes = sum(case.success for case in judged)
    met = count > 0 and successes >= TARGET_SUCCESSES * count
    return (
        f"**Success: {successes} of {count} cases ({100 * successes / max(count, 1):.0f} %); "
        f"target at least {100 * TARGET_SUCCESSES:.0f} %: {'met' if met else 'NOT met'}.** "
        f"A success is {limits.definition()}."
    )


def figures_table(judged: Sequence[CaptureCase]) -> str:
    """Median, 95th percentile and maximum of each figure over the cases that have it."""
    lines = [
        "| figure | over | cases | median | p95 | max |",
        "|---|---|---:|---:|---:|---:|",
    ]
    for name, label, over in FIGURES:
        values = np.array(_values(judged, name, over))
        cells = (
            [f"{np.median(values):.1f}", f"{np.percentile(values, 95):.1f}", f"{values.max():.1f}"]
            if len(values)
            else ["–"] * 3
        )
        lines.append(f"| {label} | {over} | {len(values)} | {' | '.join(cells)} |")
    return "\n".join(lines)


def causes_table(judged: Sequence[CaptureCase]) -> str:
    """The failed cases grouped by cause, most frequent first (a case with several
    causes counts under each)."""
    groups: dict[str, list[int]] = {}
    for case in judged:
        for fault in dict.fromkeys(cause(f) for f in case.faults):
            groups.setdefault(fault, []).append(case.index)
    failed = sum(not case.success for case in judged)
    if not groups:
        return "No case failed."
    lines = [
        f"{failed} failed case{'s' if failed != 1 else ''}, by cause:",
        "",
        "| cause | cases | which |",
        "|---|---:|---|",
    ]
    for fault, indices in sorted(groups.items(), key=lambda item: (-len(item[1]), item[0])):
        lines.append(f"| {fault} | {len(indices)} | {', '.join(map(str, indices))} |")
    return "\n".join(lines)


def failures_table(judged: Sequence[CaptureCase]) -> str:
    """Each failed case's tumble and start, and its faults in full."""
    failed = [case for case in judged if not case.success]
    if not failed:
        return ""
    lines = [
        "| case | tumble rate [deg/s] | spin axis from body x [deg] | spin, body [deg/s] "
        "| start offset [m] | why |",
        "|---:|---:|---:|---|---|---|",
    ]
    for case in failed:
        lines.append(
            f"| {case.index} | {case.rate_deg_s:.2f} | {case.axis_lean_deg:.0f} | "
            f"{_vector(case.spin_deg_s)} | {_vector(case.start_offset_m)} | "
            f"{'; '.join(case.faults)} |"
        )
    return "\n".join(lines)


def plot(judged: Sequence[CaptureCase], limits: Limits, path: Path) -> None:
    """Histograms of the four figures (with the force and turn limits) and the cases'
    tumble rate against spin-axis lean and against start offset, successes and failures
    apart."""
    plt = pyplot()
    figure, axes = plt.subplots(2, 3, figsize=(14, 8))
    lines = {"peak_contact_force_N": limits.force_N, "max_base_turn_deg": limits.turn_deg}
    for axis, (name, label, over) in zip(axes.flat, FIGURES, strict=False):
        values = _values(judged, name, over)
        axis.hist(values, bins=20, color="tab:blue", alpha=0.7)
        if name in lines:
            axis.axvline(lines[name], color="r", ls="--", label="limit")
            axis.legend()
        axis.set(xlabel=label, ylabel="cases", title=f"{over} ({len(values)})")
        axis.grid(alpha=0.3)
    for axis, x_of, xlabel in (
        (axes.flat[4], lambda c: c.axis_lean_deg, "spin axis from body x [deg]"),
        (axes.flat[5], lambda c: float(np.linalg.norm(c.start_offset_m)), "start offset [m]"),
    ):
        for success, marker, colour, name in (
            (True, "o", "tab:green", "success"),
            (False, "x", "tab:red", "failure"),
        ):
            chosen = [case for case in judged if case.success == success]
            axis.scatter(
                [x_of(case) for case in chosen],
                [case.rate_deg_s for case in chosen],
                marker=marker,
                color=colour,
                label=f"{name} ({len(chosen)})",
            )
        axis.set(xlabel=xlabel, ylabel="tumble rate [deg/s]")
        axis.legend()
        axis.grid(alpha=0.3)
    figure.suptitle("Capture of a tumbling target: dispersed cases")
    save(figure, path)


def limits_of(campaign: Campaign) -> Limits:
    """The limits of a capture campaign's base scenario.

    Raises
    ------
    DcsimError
        If the campaign's scenario is not a capture, or its metrics leave out a summary
        field the judgement reads.
    """
    limits = Limits.of(validate(campaign.base))
    missing = [
        name for name in ("captured", "detumbled", *_FIELDS) if name not in campaign.spec.metrics
    ]
    if missing:
        raise DcsimError(
            f"dcsim bench capture judges each case by {', '.join(missing)}: add them to the "
            "campaign's `metrics`"
        )
    return limits


def _values(judged: Sequence[CaptureCase], name: str, over: str) -> list[float]:
    """Figure ``name`` of the cases it is taken ``over`` (:data:`FIGURES`)."""
    chosen = (c for c in judged if over != TOUCHED or not math.isnan(c.figures["contact_time_s"]))
    return [case.figures[name] for case in chosen if not math.isnan(case.figures[name])]


def _number(value: Any) -> float:
    """A summary value as a float; NaN for a missing one."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def _true(value: Any) -> bool:
    """Whether a summary flag read back from the table is set (NaN is not)."""
    number = _number(value)
    return not math.isnan(number) and number != 0.0


def _triple(values: Any) -> tuple[float, float, float]:
    x, y, z = (float(v) for v in values)
    return x, y, z


def _vector(values: Sequence[float]) -> str:
    return "[" + ", ".join(f"{v:+.2f}" for v in values) + "]"
