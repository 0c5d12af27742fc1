"""Campaign files and their cases, without a cluster: validation, seeds, draws, overrides."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from dcsim.campaign import campaign_cases, load_campaign
from dcsim.campaign.cases import case_document, draw_seed, override_text
from dcsim.campaign.results import axis_label, metric_names
from dcsim.errors import CampaignError
from dcsim.registry.discovery import PluginRegistry
from dcsim.scenario import validate
from dcsim.scenario.yamltext import compose

REPO = Path(__file__).resolve().parents[2]
DEFAULT = REPO / "scenarios" / "default.yaml"
SHIPPED = sorted((REPO / "scenarios" / "campaigns").glob("*.yaml"))


@pytest.fixture(scope="module")
def registry() -> PluginRegistry:
    return PluginRegistry.discover()


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "campaign.yaml"
    path.write_text(textwrap.dedent(text).lstrip().replace("BASE", str(DEFAULT)))
    return path


def cases_of(tmp_path: Path, text: str, registry: PluginRegistry, count: int | None = None):
    return campaign_cases(load_campaign(write(tmp_path, text)), registry, count)


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.name)
def test_shipped_campaigns_give_valid_cases(path, registry):
    campaign = load_campaign(path)
    cases = campaign_cases(campaign, registry)
    assert len(cases) == campaign.spec.total_cases
    metric_names(campaign, validate(campaign.base).mission.type)


def test_plot_axes_name_the_values_in_words_with_their_units(tmp_path):
    campaign = load_campaign(REPO / "scenarios" / "campaigns" / "default_dispersed.yaml")
    assert axis_label(campaign, "robot.initial.position[0]") == "robot initial position, radial [m]"
    assert axis_label(campaign, "robot.initial.velocity[2]") == (
        "robot initial velocity, orbit-normal [m/s]"
    )
    assert axis_label(campaign, "beacons.noise_sigma") == "beacons noise sigma [m]"
    assert axis_label(campaign, "delta_v_mps") == "delta v [m/s]"
    assert axis_label(campaign, "delivered") == "delivered"
    geocentric = write(
        tmp_path,
        """
        name: g
        scenario: THESIS
        dispersions:
          robot.initial.attitude: {type: uniform, low: 0, high: 1}
          robot.initial.position: {type: uniform, low: 0, high: 1}
        """.replace("THESIS", str(REPO / "scenarios" / "thesis_debris_field.yaml")),
    )
    campaign = load_campaign(geocentric)
    assert axis_label(campaign, "robot.initial.position[1]") == "robot initial position, y [m]"
    assert axis_label(campaign, "robot.initial.attitude[3]") == "robot initial attitude [3]"


def test_case_seeds_come_from_spawn_by_index(tmp_path, registry):
    cases = cases_of(tmp_path, "name: c\nscenario: BASE\nseed: 11\ncases: 5\n", registry)
    spawned = np.random.SeedSequence(11).spawn(5)
    expected = [int(s.generate_state(1, np.uint32)[0]) & (2**31 - 1) for s in spawned]
    assert [case.seed for case in cases] == expected
    assert all(f"world.seed={case.seed}" in case.overrides for case in cases)


def test_first_cases_are_the_same_whatever_the_count(tmp_path, registry):
    text = """
        name: c
        scenario: BASE
        seed: 4
        cases: 6
        grid: {controller.plugin: [pd, elastic]}
        dispersions:
          beacons.noise_sigma: {type: uniform, low: 0.01, high: 0.2}
          robot.initial.position: {type: normal, sigma: 1.0}
    """
    every = cases_of(tmp_path, text, registry)
    assert len(every) == 12
    assert cases_of(tmp_path, text, registry, 5) == every[:5]


def test_grid_points_share_each_draw(tmp_path, registry):
    text = """
        name: c
        scenario: BASE
        cases: 3
        grid: {controller.plugin: [pd, elastic], robot.max_force: [2.0, 5.0]}
        dispersions:
          beacons.noise_sigma: {type: uniform, low: 0.01, high: 0.2}
    """
    cases = cases_of(tmp_path, text, registry)
    assert len(cases) == 12
    for draw in range(3):
        mine = cases[4 * draw : 4 * draw + 4]
        assert {c.draw for c in mine} == {draw}
        assert len({c.seed for c in mine}) == 1
        assert len({c.values["beacons.noise_sigma"] for c in mine}) == 1
        points = {(c.values["controller.plugin"], c.values["robot.max_force"]) for c in mine}
        assert len(points) == 4


def test_adding_a_dispersion_keeps_the_others_values(tmp_path, registry):
    one = """
        name: c
        scenario: BASE
        cases: 4
        dispersions:
          beacons.noise_sigma: {type: uniform, low: 0.01, high: 0.2}
    """
    two = one + "      robot.mass: {type: normal, sigma: 5.0}\n"
    first = cases_of(tmp_path, one, registry)
    second = cases_of(tmp_path, two, registry)
    assert [c.values["beacons.noise_sigma"] for c in first] == [
        c.values["beacons.noise_sigma"] for c in second
    ]


def test_draws_follow_their_distributions(tmp_path, registry):
    text = """
        name: c
        scenario: BASE
        cases: 400
        dispersions:
          robot.initial.position: {type: normal, sigma: [2.0, 1.0, 0.0], low: [-3, -5, -1], high: [3, 5, 1]}
          robot.initial.velocity: {type: uniform, low: [-0.01, 0, 0.02], high: [0.01, 0.0, 0.03]}
          beacons.noise_sigma: {type: normal, mean: 0.1, sigma: 0.01}
          controller.plugin: {type: choice, values: [pd, elastic], weights: [3, 1]}
          world.seed: {type: seed}
    """
    cases = cases_of(tmp_path, text, registry)
    position = np.array([c.values["robot.initial.position"] for c in cases])
    assert np.all(np.abs(position[:, 0]) <= 3) and np.abs(position[:, 0]).max() > 2.5
    assert position[:, 1].std() == pytest.approx(1.0, rel=0.15)
    assert np.all(position[:, 2] == 0.0)  # sigma 0: the nominal value
    velocity = np.array([c.values["robot.initial.velocity"] for c in cases])
    assert np.all((velocity >= [-0.01, 0, 0.02]) & (velocity <= [0.01, 0, 0.03]))
    noise = np.array([c.values["beacons.noise_sigma"] for c in cases])
    assert noise.mean() == pytest.approx(0.1, abs=0.002)
    chosen = [c.values["controller.plugin"] for c in cases]
    assert chosen.count("pd") / len(chosen) == pytest.approx(0.75, abs=0.07)
    assert [c.values["world.seed"] for c in cases] == [c.seed for c in cases]
    assert all(sum(o.startswith("world.seed=") for o in c.overrides) == 1 for c in cases)


def test_a_case_is_the_base_with_its_overrides(tmp_path, registry):
    text = """
        name: c
        scenario: BASE
        seed: 9
        cases: 2
        set: {world.duration: 30.0}
        dispersions:
          robot.initial.position: {type: uniform, low: -1.0, high: 1.0}
    """
    campaign = load_campaign(write(tmp_path, text))
    case = campaign_cases(campaign, registry)[1]
    scenario = validate(case_document(campaign.base, case))
    assert scenario.world.duration == 30.0
    assert scenario.world.seed == case.seed == draw_seed(9, 1)
    assert list(scenario.robot.initial.position) == case.values["robot.initial.position"]
    assert validate(campaign.base).world.duration == 900.0  # the base is untouched


@pytest.mark.parametrize(
    ("body", "where", "words"),
    [
        ("cases: 0\n", ":3:1: cases", "greater than or equal to 1"),
        (
            "dispersions:\n  robot.mas: {type: uniform, low: 1, high: 2}\n",
            "robot.mas",
            "names no key",
        ),
        (
            "dispersions:\n  robot.mass: {type: gaussian, sigma: 1}\n",
            "dispersions.robot.mass",
            "does not match any of the expected tags",
        ),
        ("dispersions:\n  robot.mass: {type: normal, sigma: -1}\n", "sigma", "≥ 0"),
        (
            "dispersions:\n  robot.mass: {type: uniform, low: 3, high: 2}\n",
            "robot.mass",
            "low is above",
        ),
        (
            "dispersions:\n  robot.initial.position: {type: uniform, low: [0, 0], high: [1, 1]}\n",
            "robot.initial.position",
            "different lengths",
        ),
        ("set: {world.seed: 3}\ngrid: {world.seed: [1, 2]}\n", "grid.world.seed", "also in set"),
        ("grid: {'robot..mass': [1]}\n", "robot..mass", "is not a key path"),
        ("metrics: [delta_v, delivered]\n", "metrics", "delta_v: not in the summary"),
    ],
)
def test_invalid_campaigns_are_refused_with_their_place(tmp_path, registry, body, where, words):
    path = write(tmp_path, "name: c\nscenario: BASE\n" + body)
    with pytest.raises(CampaignError) as caught:
        campaign = load_campaign(path)
        campaign_cases(campaign, registry)
        metric_names(campaign, "debris")
    message = str(caught.value)
    assert message.startswith(f"{path}: invalid campaign")
    assert where in message and words in message


def test_cases_that_are_invalid_scenarios_are_refused_before_running(tmp_path, registry):
    text = """
        name: c
        scenario: BASE
        cases: 50
        dispersions:
          robot.mass: {type: normal, mean: 1.0, sigma: 2.0}
    """
    with pytest.raises(CampaignError) as caught:
        cases_of(tmp_path, text, registry)
    message = str(caught.value)
    assert "case " in message and "robot.mass" in message and "more invalid cases" in message


def test_a_missing_base_scenario_is_named(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text("name: c\nscenario: nowhere.yaml\n")
    with pytest.raises(CampaignError, match="cannot use the base scenario .*nowhere.yaml"):
        load_campaign(path)


plain = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-(10**12), 10**12)
    | st.floats(allow_nan=False, allow_infinity=False)
    | st.text(max_size=12),
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner, max_size=3)
    ),
    max_leaves=10,
)


@given(plain)
def test_override_text_reads_back_equal(value):
    key, _, text = override_text("robot.mass", value).partition("=")
    assert key == "robot.mass"
    assert compose(text)[1] == value  # as dcsim run --set reads it
