"""verify.falsify.scenarios: each family builds a valid scenario with the geometry its name promises."""

from __future__ import annotations

import math

import numpy as np
import pytest

import verify
from tubekit import load_scenario
from tubekit.scenario import Scenario
from verify.falsify import scenarios as fam

BASE = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")
UNITS = np.random.default_rng(11).uniform(0, 1, (12, 6))


def _start(sc: Scenario) -> np.ndarray:
    return np.asarray(sc.initial_state[:3])


@pytest.mark.parametrize("name", sorted(fam.FAMILIES))
def test_every_family_builds_separated_obstacles_clear_of_the_start(name):
    for u in UNITS:
        sc = fam.FAMILIES[name](BASE, u[:fam.FAMILY_DIMS[name]])
        rbar = sc.vehicle_radius
        for i, a in enumerate(sc.obstacles):
            assert np.linalg.norm(np.subtract(a.center, _start(sc))) - a.radius - rbar > fam.START_CLEARANCE
            for b in sc.obstacles[i + 1:]:
                gap = np.linalg.norm(np.subtract(a.center, b.center))
                assert gap > 2 * (rbar + fam.SEPARATION_MARGIN) + a.radius + b.radius


def test_beyond_sensing_obstacles_are_unseen_at_the_start_but_close():
    for u in UNITS:
        sc = fam.beyond_sensing_from_unit(BASE, u[:3])
        (o,) = sc.obstacles
        surface = np.linalg.norm(np.subtract(o.center, _start(sc))) - o.radius
        assert sc.sensing_range < surface <= sc.sensing_range + 0.3 + 1e-9


def test_on_path_obstacles_are_centred_on_the_desired_path():
    for u in UNITS:
        sc = fam.on_path_from_unit(BASE, u)
        path = np.asarray(BASE.trajectory.position(np.linspace(0.0, BASE.duration, 20001)))
        for o in sc.obstacles:
            assert np.min(np.linalg.norm(path - np.asarray(o.center), axis=1)) < 0.01


def test_clusters_are_tight():
    """Neighbours of a cluster are at most 20 % farther apart than the separation requires."""
    sc = fam.cluster_from_unit(BASE, np.array([1.0, 0.5, 1.0, 0.5, 0.5, 0.0]))
    assert len(sc.obstacles) >= 3
    r, rbar = sc.obstacles[0].radius, sc.vehicle_radius
    need = 2 * (rbar + fam.SEPARATION_MARGIN) + 2 * r
    nearest = [min(np.linalg.norm(np.subtract(a.center, b.center)) for b in sc.obstacles if b is not a)
               for a in sc.obstacles]
    assert need < min(nearest) and max(nearest) <= 1.2 * need + 1e-9


def test_between_end_and_target_lies_on_the_segment():
    u = np.array([0.0, 0.5, 0.5])
    sc = fam.between_end_and_target_from_unit(BASE, u)
    target = np.asarray(BASE.trajectory.position(np.array([BASE.controller.horizon]))[0])
    end = target + _start(BASE) - np.asarray(BASE.trajectory.position(np.array([0.0]))[0])
    assert np.allclose(sc.obstacles[0].center, 0.5 * (end + target))


def test_a_blocked_start_faces_a_close_obstacle():
    for u in UNITS:
        sc = fam.blocked_start_from_unit(BASE, u[:3])
        (o,) = sc.obstacles
        rel = np.subtract(o.center, _start(sc))
        clear = np.linalg.norm(rel) - o.radius - sc.vehicle_radius
        assert 0.03 - 1e-9 <= clear <= 0.3 + 1e-9
        assert math.atan2(rel[1], rel[0]) == pytest.approx(sc.initial_state[3])
