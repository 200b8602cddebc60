"""tubekit.plotting.framing: the top view zooms on the path; far obstacles and a wide sensing range stay out."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tubekit.plotting.framing import NEAR_PATH_M, desired_curve, end_time, frame_of, obstacles_near
from tubekit.scenario import load_scenario, paper_scenario

ROOT = Path(__file__).resolve().parents[1]


def path_columns(start, velocity, seconds: float, rate_hz: float = 20.0) -> dict[str, np.ndarray]:
    """A straight run from ``start`` (x, y, z) at ``velocity`` (m/s), its nominal on it: the columns a top view reads."""
    t = np.arange(0.0, seconds + 1e-9, 1.0 / rate_hz)
    p = np.asarray(start, dtype=float)[None] + t[:, None] * np.asarray(velocity, dtype=float)[None]
    return {"t": t, "step": np.floor(t / 0.1).astype(int), "x": p[:, 0], "y": p[:, 1], "z": p[:, 2],
            "x_hat": p[:, 0].copy(), "y_hat": p[:, 1].copy(), "backup_active": np.zeros(t.size)}


@pytest.fixture(scope="module")
def slow():
    """examples/bluerov2_slow.toml: a 15 m sensing range, obstacles 17 m from the circle's centre."""
    return load_scenario(ROOT / "examples" / "bluerov2_slow.toml")


def test_a_15_m_sensing_range_does_not_set_the_frame(slow):
    """Issue 35 item 4: the frame is within a few metres of a 2 m path, not the 30 m sensing circle."""
    run = ("tube", path_columns((-1.0, 3.0, 0.2), (0.08, 0.0, 0.0), 20.0))
    frame = frame_of(slow, [run])
    assert frame.sensing is False and frame.obstacles == ()
    path_x = (-1.0, 0.6)
    target = desired_curve(slow, 20.0)
    lo_x = min(path_x[0], target[:, 0].min())
    hi_x = max(path_x[1], target[:, 0].max())
    assert lo_x - 1.0 < frame.x[0] < lo_x and hi_x < frame.x[1] < hi_x + 1.0
    assert frame.width < 5.0 and frame.height < 5.0


def test_the_paper_frame_keeps_its_obstacles_and_sensing_circles():
    """On the paper's scenario (R̄ = 1.5 m, obstacles 3 m from the centre) everything fits, as before."""
    sc = paper_scenario()
    run = ("tube", path_columns((-0.5, 3.0, 0.0), (0.3, -0.2, 0.0), 10.0))
    frame = frame_of(sc, [run])
    assert frame.obstacles == (0, 1) and frame.sensing is True
    assert frame.x[0] < -3.6 and frame.x[1] > 3.6  # both inflated obstacles inside


def test_an_obstacle_is_near_within_the_reach_of_the_path_box():
    sc = paper_scenario()  # obstacles at (+-3, 0, 0), radius 0.4, vehicle radius 0.2: inflated 0.6
    lo, hi = np.array([0.0, 0.0]), np.array([1.0, 1.0])
    assert obstacles_near(sc, lo, hi, reach=1.4 + 1e-9) == (0,)  # (3, 0): 2 m from the box, 1.4 from its disc
    assert obstacles_near(sc, lo, hi, reach=1.3) == ()
    assert NEAR_PATH_M == 1.0


def test_end_time_is_the_first_runs_or_the_scenarios():
    sc = paper_scenario()
    assert end_time(sc, [("a", {"t": np.array([0.0, 2.5])})]) == 2.5 and end_time(sc, []) == sc.duration
