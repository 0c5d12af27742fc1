"""``dcsim bench capture``: dispersed captures judged against the capture's targets."""

from __future__ import annotations

import math

import pandas
import pytest
import yaml
from click.testing import CliRunner

from dcsim.api import load_scenario
from dcsim.bench.capture import cause, judge, limits_of, markdown
from dcsim.campaign import campaign_cases, load_campaign
from dcsim.cli.main import cli
from dcsim.registry.discovery import PluginRegistry
from tests.conftest import CAPTURE, REPO

CAMPAIGN = REPO / "scenarios" / "campaigns" / "debris_capture_dispersed.yaml"

CAPTURED = {
    "status": "completed",
    "reason": "target captured and detumbled",
    "captured": True,
    "detumbled": True,
    "contact_time_s": 80.0,
    "latch_time_s": 82.0,
    "detumble_time_s": 5.0,
    "peak_contact_force_N": 400.0,
    "max_base_turn_deg": 3.0,
    "final_target_rate_deg_s": 0.05,
}
NOT_TOUCHED = {
    "captured": False,
    "detumbled": False,
    "contact_time_s": None,
    "latch_time_s": None,
    "detumble_time_s": None,
    "peak_contact_force_N": 0.0,
    "max_base_turn_deg": 0.01,
    "final_target_rate_deg_s": 3.0,
}
ROWS = [
    CAPTURED,
    {
        **NOT_TOUCHED,
        "status": "stopped",
        "reason": "no path: near a singularity (9x, last det(J Jᵀ) 1.68e-09)",
    },
    {**CAPTURED, "peak_contact_force_N": 1600.0, "max_base_turn_deg": 6.0, "arm_links_struck": 2},
    {
        **CAPTURED,
        "status": "stopped",
        "reason": "the run reached its duration",
        "detumbled": False,
        "detumble_time_s": None,
        "final_target_rate_deg_s": 0.4,
    },
    {"status": "failed", "reason": "worker died"},
]


@pytest.fixture(scope="module")
def shipped():
    """The shipped capture campaign and its first five cases."""
    campaign = load_campaign(CAMPAIGN)
    return campaign, campaign_cases(campaign, PluginRegistry.discover(), len(ROWS))


def test_like_faults_group_without_their_numbers():
    assert cause("no path: near a singularity (9x, last det(J Jᵀ) 1.68e-09); x (1x, 5 s)") == (
        "no path: near a singularity; x"
    )
    refusal = "not captured: no approach path: the straight path passes {} m from obstacle {}."
    assert cause(refusal.format(6.33, 1)) == cause(refusal.format(6.2, 12))
    assert cause(refusal.format(6.33, 1)) == (
        "not captured: no approach path: the straight path passes … m from obstacle …."
    )
    assert cause("failed: joint_1 at -1.5E-3 rad, v1.2") == "failed: joint_1 at … rad, v1.2"
    assert cause("contact force above the gripper's 1500 N") == (
        "contact force above the gripper's 1500 N"  # the bench's own limit is kept
    )
    assert cause("not detumbled to 0.1 deg/s (target at 0.40 deg/s): run 3 ended") == (
        "not detumbled to 0.1 deg/s: run … ended"
    )


def test_every_limit_is_judged_and_every_failure_says_why(shipped):
    campaign, cases = shipped
    table = pandas.DataFrame([{"case": i, **row} for i, row in enumerate(ROWS)])
    judged = judge(campaign, cases, table, limits_of(campaign))
    assert [case.success for case in judged] == [True, False, False, False, False]
    assert judged[1].faults == (
        "not captured: no path: near a singularity (9x, last det(J Jᵀ) 1.68e-09)",
    )
    assert judged[2].faults == (
        "contact force above the gripper's 1500 N",
        "base turned more than 5 deg",
        "the arm struck the target (2 links)",
    )
    assert judged[3].faults == (
        "not detumbled to 0.1 deg/s (target at 0.40 deg/s): the run reached its duration",
    )
    assert judged[4].faults == ("failed: worker died",)
    values = cases[1].values["mission.target.angular_velocity_deg_s"]
    assert judged[1].rate_deg_s == pytest.approx(math.hypot(*values))
    assert judged[1].axis_lean_deg == pytest.approx(
        math.degrees(math.atan2(math.hypot(values[1], values[2]), values[0]))
    )
    start = cases[1].values["robot.initial.position"]
    shipped_start = load_scenario(CAPTURE).robot.initial.position
    offset = [a - b for a, b in zip(start, shipped_start, strict=True)]
    assert judged[1].start_offset_m == pytest.approx(offset)

    text = markdown(judged, limits_of(campaign))
    assert "**Success: 1 of 5 cases (20 %); target at least 95 %: NOT met.**" in text
    # force and turn over the three cases that touched; the times where they happened
    assert "| peak contact force [N] | cases that touched the target | 3 | 400.0 |" in text
    assert "| detumble time, latch to still [s] | detumbled cases | 2 | 5.0 |" in text
    assert "| capture (latch) time from the start [s] | captured cases | 3 | 82.0 |" in text
    assert "| not captured: no path: near a singularity | 1 | 1 |" in text
    assert "\n| 2 | " in text and "\n| 0 | " not in text  # failed cases listed, not successes


def test_a_campaign_at_the_least_options_runs_judges_and_resumes(tmp_path):
    out, plot = tmp_path / "campaign", tmp_path / "capture.png"
    options = ["--cases", "1", "--workers", "1", "--duration", "0.01", "--out", str(out)]
    first = CliRunner().invoke(cli, ["bench", "capture", *options, "--plot", str(plot)])
    assert first.exit_code == 0, first.output
    assert "**Success: 0 of 1 cases (0 %); target at least 95 %: NOT met.**" in first.stdout
    assert "| 0 | " in first.stdout  # the case that did not capture, listed
    assert plot.exists() and (out / "results.csv").exists()
    again = CliRunner().invoke(cli, ["bench", "capture", "--resume", str(out)])
    assert again.exit_code == 0, again.output
    assert again.stdout == first.stdout.replace(f"\nplot: {plot}\n", "")


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (
            [str(REPO / "scenarios" / "campaigns" / "default_dispersed.yaml")],
            "the campaign's scenario is a 'debris' mission: name a campaign of a capture",
        ),
        (["--cases", "101"], "the campaign has 100 cases"),
        (["--resume", ".", "--duration", "1"], "drop CAMPAIGN, --out and --duration"),
    ],
)
def test_what_cannot_be_benched_is_refused_before_anything_runs(arguments, message):
    result = CliRunner().invoke(cli, ["bench", "capture", *arguments])
    assert result.exit_code == 2
    assert message in result.output


def test_a_campaign_whose_metrics_leave_out_a_judged_field_is_refused(tmp_path):
    """Without ``arm_links_struck`` among the metrics, a strike could not fail a case."""
    data = yaml.safe_load(CAMPAIGN.read_text())
    data["scenario"] = str(CAMPAIGN.parent / data["scenario"])
    data["metrics"].remove("arm_links_struck")
    campaign = tmp_path / "campaign.yaml"
    campaign.write_text(yaml.safe_dump(data))
    result = CliRunner().invoke(cli, ["bench", "capture", str(campaign)])
    assert result.exit_code == 2
    assert "judges each case by arm_links_struck: add them to the campaign's `metrics`" in (
        result.output
    )
