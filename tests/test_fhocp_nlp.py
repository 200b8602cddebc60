"""The discretised NLP: rollout, obstacle selection and the nonlinear-constraint violations."""

from __future__ import annotations

import numpy as np
import pytest

from tubekit.fhocp_nlp import FhocpNlp, discrete_step, obstacle_array, rollout, select_obstacles
from tubekit.scenario import Obstacle, paper_scenario
from tubekit.tightening import Tightening

SC = paper_scenario()
TIGHT = Tightening(v_max=np.array([0.3, 0.2, 0.4]), e_d_min=0.3, e_o_max=0.8, e_z_max=0.9, e_d_max=2.9,
                   obstacle_margin=0.05, rho_tilde=0.05, sigma=10.0)
NLP = FhocpNlp.from_scenario(SC, TIGHT, terminal="off")


def test_rollout_is_repeated_discrete_step():
    rng = np.random.default_rng(0)
    s0 = np.array([0.5, -1.0, 0.2, 0.3])
    v = rng.uniform(-0.3, 0.3, (NLP.n, 3))
    s = rollout(s0, v, NLP.dt)
    x = s0
    for k in range(NLP.n):
        x = discrete_step(x, v[k], NLP.dt)
        assert np.allclose(s[k + 1], x, atol=1e-12)


def test_obstacle_violation_is_the_penetration_depth():
    """A stationary plan at distance d from an obstacle centre violates by r + r_bar + margin - d."""
    ob = Obstacle((1.0, 0.0, 0.0), 0.4)
    s0 = np.array([1.3, 0.0, 0.0, 0.0])            # 0.3 m from the centre
    v = np.zeros((NLP.n, 3))
    states = rollout(s0, v, NLP.dt)
    ref = np.tile([1.3, -1.0, 0.0], (NLP.n + 1, 1))  # target 1 m away: e_d constraint inactive
    ev = NLP.evaluate(states, v, ref, obstacle_array([ob]))
    assert ev.violations["obstacle"] == pytest.approx(0.4 + SC.vehicle_radius + 0.05 - 0.3)
    assert ev.violations["e_d_min"] == 0.0


def test_e_d_and_input_violations():
    s0 = np.array([0.0, 0.1, 0.0, 0.0])
    v = np.zeros((NLP.n, 3))
    v[0, 0] = 0.5                                     # 0.2 above V-bar_u = 0.3
    states = rollout(s0, np.clip(v, -TIGHT.v_max, TIGHT.v_max), NLP.dt)
    ref = np.zeros((NLP.n + 1, 3))                    # target at the origin, e_d ~ 0.1 < 0.3
    ev = NLP.evaluate(states, v, ref, np.zeros((0, 4)))
    assert ev.violations["input"] == pytest.approx(0.2)
    e_d = np.hypot(states[1:, 0], states[1:, 1])
    assert ev.violations["e_d_min"] == pytest.approx(np.max(0.3 - e_d))


def test_select_obstacles_by_surface_distance_nearest_first():
    obs = [Obstacle((5.0, 0, 0), 0.5), Obstacle((2.0, 0, 0), 0.4), Obstacle((1.5, 0, 3.0), 0.4)]
    kept, dropped = select_obstacles(np.zeros(4), obs, sensing_range=1.6, max_count=1)
    # surface distances: 4.5, 1.6, ~2.95 -> only the second is in range
    assert kept.shape == (1, 4) and np.allclose(kept[0], [2.0, 0, 0, 0.4]) and dropped == 0
    kept, dropped = select_obstacles(np.zeros(4), obs, sensing_range=10.0, max_count=2)
    assert np.allclose(kept[:, 0], [2.0, 1.5]) and dropped == 1
