"""tubekit.app.campaign_spec: the ``obstacles = { cluster = {...} }`` distribution (issue 21)."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from tubekit.exceptions import ConfigError
from tubekit.app.campaign_spec import draw_cluster, spec_from_dict, spec_from_stored

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = (ROOT / "verify" / "scenarios" / "paper_currents.toml").as_posix()
CLUSTER = {"count": [3, 7], "radius": [0.15, 0.4], "gap": [0.01, 0.3],
           "center": [[0.5, 1.2, -0.2], [2.6, 2.9, 0.2]], "margin": 0.15}


def _spec(cluster=None, **sample):
    entry = {"obstacles": {"cluster": CLUSTER if cluster is None else cluster}, **sample}
    return spec_from_dict({"scenario": SCENARIO, "runs": 30, "seed": 4, "duration": 5.0, "sample": entry})


def test_clusters_are_separated_as_certify_requires_and_clear_of_the_start():
    spec = _spec(**{"initial_state": {"uniform": [[-1.1, 2.7, -0.3, -0.2], [-0.6, 3.3, 0.3, 0.2]]}})
    counts = []
    for k in range(30):
        sc = spec.plan(k).scenario
        counts.append(len(sc.obstacles))
        start = np.asarray(sc.initial_state[:3])
        for o in sc.obstacles:
            assert np.linalg.norm(np.subtract(o.center, start)) > o.radius + sc.vehicle_radius
            assert 0.15 <= o.radius <= 0.4
        for a, b in itertools.combinations(sc.obstacles, 2):
            gap = np.linalg.norm(np.subtract(a.center, b.center))
            assert gap > 2 * (sc.vehicle_radius + 0.15) + a.radius + b.radius
    assert min(counts) >= 1 and max(counts) <= 7 and len(set(counts)) > 2


def test_neighbours_are_at_most_the_drawn_gap_apart():
    params = {**CLUSTER, "count": [7, 7], "gap": [0.1, 0.1], "vehicle_radius": 0.2}
    obstacles = draw_cluster(params, np.random.default_rng(0))
    r = obstacles[0]["radius"]
    spacing = (2 * (0.2 + 0.15) + 2 * r) * 1.1
    d = [np.linalg.norm(np.subtract(obstacles[0]["center"], o["center"])) for o in obstacles[1:]]
    assert len(obstacles) == 7 and np.allclose(d, spacing)


def test_the_cluster_spec_round_trips_through_campaign_json():
    spec = _spec()
    again = spec_from_stored(spec.to_dict())
    assert again.fingerprint == spec.fingerprint
    assert again.plan(3).scenario.obstacles == spec.plan(3).scenario.obstacles


@pytest.mark.parametrize("cluster, field", [
    ({**CLUSTER, "extra": 1}, "sample.obstacles.cluster"),
    ({k: v for k, v in CLUSTER.items() if k != "gap"}, "sample.obstacles.cluster"),
    ({**CLUSTER, "count": [0, 3]}, "sample.obstacles.cluster.count"),
    ({**CLUSTER, "count": [3, 40]}, "sample.obstacles.cluster.count"),
    ({**CLUSTER, "count": [3.0, 4]}, "sample.obstacles.cluster.count"),
    ({**CLUSTER, "radius": [0.0, 0.2]}, "sample.obstacles.cluster.radius"),
    ({**CLUSTER, "gap": [0.3, 0.1]}, "sample.obstacles.cluster.gap"),
    ({**CLUSTER, "center": [[0, 0], [1, 1]]}, "sample.obstacles.cluster.center"),
    ({**CLUSTER, "margin": -0.1}, "sample.obstacles.cluster.margin"),
])
def test_a_bad_cluster_names_its_field(cluster, field):
    with pytest.raises(ConfigError, match=field.replace(".", r"\.")):
        _spec(cluster)


def test_cluster_is_only_for_obstacles():
    with pytest.raises(ConfigError, match=r"sample\.initial_state"):
        spec_from_dict({"scenario": SCENARIO, "runs": 2, "seed": 1,
                        "sample": {"initial_state": {"cluster": CLUSTER}}})


def test_the_recorded_obstacles_are_those_that_ran():
    spec = _spec(**{"initial_state": {"uniform": [[0.5, 1.2, -0.1, 0.0], [2.6, 2.9, 0.1, 0.0]]}})
    for k in range(10):
        plan = spec.plan(k)
        assert [tuple(o["center"]) for o in plan.values["obstacles"]] == [o.center for o in plan.scenario.obstacles]


DYNAMIC = (ROOT / "examples" / "bluerov2_currents.toml").as_posix()


def _truth_spec(entry=None, scenario: str = DYNAMIC):
    return spec_from_dict({"scenario": scenario, "runs": 40, "seed": 2, "duration": 5.0,
                           "sample": {"plant.truth": {"box": True} if entry is None else entry}})


def test_the_truth_box_draws_every_interval_coefficient_inside_its_interval():
    """Property: each run's plant is a point of the vehicle's box, and every run shares one certificate."""
    from tubekit.app.certified import input_key
    spec = _truth_spec()
    params = spec.plan(0).scenario.plant.params
    names = set(params.interval_fields)
    keys, seen = set(), []
    for k in range(40):
        sc = spec.plan(k).scenario
        truth = dict(sc.plant.truth)
        assert set(truth) == names
        for name, value in truth.items():
            lo, hi = params.interval(name)
            assert lo <= value <= hi
        keys.add(input_key(sc))
        seen.append(truth["Y_vv"])
    assert len(keys) == 1                       # the truth is not a certificate input
    lo, hi = params.interval("Y_vv")
    assert min(seen) < lo + 0.25 * (hi - lo) and max(seen) > hi - 0.25 * (hi - lo)  # spread over the box
    assert spec_from_stored(spec.to_dict()).plan(7).values == spec.plan(7).values


@pytest.mark.parametrize("entry, scenario, match", [
    ({"box": False}, DYNAMIC, r"sample\.plant\.truth"),
    ({"uniform": [0, 1]}, DYNAMIC, r"sample\.plant\.truth"),
    (None, SCENARIO, r"sample\.plant\.truth.*dynamic plant"),  # the kinematic plant simulates no coefficient
])
def test_a_bad_truth_entry_names_its_field(entry, scenario, match):
    with pytest.raises(ConfigError, match=match):
        _truth_spec(entry, scenario)


@pytest.mark.parametrize("name", ["keep_moving_campaign.toml", "keep_moving_tracked_campaign.toml"])
def test_the_keep_moving_campaigns_sample_currents_within_what_their_scenario_certifies(name):
    """examples/keep_moving_campaign.toml and its tracked twin: the sampled amplitudes stay at or below the
    scenario's own (the bound its certificate holds over), and the scenario keeps its surge floor and its loiter."""
    from tubekit.app.campaign_spec import load_spec
    spec = load_spec(ROOT / "examples" / name)
    assert spec.runs == 200 and spec.falsify_sequences == 1
    assert spec.base["limits"]["u_min"] == 0.2 and spec.base["controller"]["backup"] == "loiter"
    high = dict(spec.sample)["disturbance.amplitude"].to_dict()["uniform"][1]
    assert all(h <= a for h, a in zip(high, spec.base["disturbance"]["amplitude"]))


def test_the_bluerov2_current_campaign_draws_only_the_truth_of_its_certified_box():
    """examples/bluerov2_current_campaign.toml: one certificate (the paper's current on the Heavy), 200 runs that
    differ only in the vehicle as simulated, a point of the certificate's coefficient box."""
    from tubekit.app.campaign_spec import load_spec
    spec = load_spec(ROOT / "examples" / "bluerov2_current_campaign.toml")
    assert spec.runs == 200 and [k for k, _ in spec.sample] == ["plant.truth"]
    assert spec.base["disturbance"]["amplitude"] == [0.1, 0.1, 0.1] and spec.base["plant"]["kind"] == "dynamic"


@pytest.mark.parametrize("name, spread", [("bluerov2_spread", 0.2), ("bluerov2_brisk_current", 0.1)])
def test_the_spread_campaigns_draw_only_the_truth_of_their_wider_boxes(name, spread):
    """examples/bluerov2_spread_campaign.toml and bluerov2_brisk_current_campaign.toml: 200 runs that differ only in
    the vehicle as simulated, drawn in a box of von Benzon's values ± ``spread`` (X_uu = -141 kg/m at the centre)
    with the velocity loop at 20 rad/s."""
    from tubekit.app.campaign_spec import load_spec
    spec = load_spec(ROOT / "examples" / f"{name}_campaign.toml")
    assert spec.runs == 200 and [k for k, _ in spec.sample] == ["plant.truth"]
    vehicle = spec.base["plant"]["vehicle"]
    assert vehicle["loop_bandwidth"] == 20.0
    assert vehicle["X_uu"] == pytest.approx([-141.0 * (1 + spread), -141.0 * (1 - spread)])



def test_the_published_campaign_draws_the_drag_and_the_top_speed_and_derives_the_thrust():
    """Property: examples/remus100_published_campaign.toml draws every interval coefficient but X_max, which each run
    takes from its drawn drag and top speed (X_max = |X_uu| s²), inside the published interval."""
    from tubekit.app.campaign_spec import load_spec
    spec = load_spec(ROOT / "examples" / "remus100_published_campaign.toml")
    assert spec.runs == 200 and sorted(k for k, _ in spec.sample) == ["disturbance.period", "plant.truth"]
    for k in range(10):
        plant = spec.plan(k).scenario.plant
        assert "X_max" not in dict(plant.truth) and {"X_uu", "top_speed"} <= set(dict(plant.truth))
        truth = plant.truth_params
        assert truth.X_max == pytest.approx(abs(truth.X_uu) * truth.top_speed ** 2, rel=1e-12)
        assert 10.1 <= truth.X_max <= 41.2
