"""tubekit.settings: each component's settings validate themselves, naming the field."""

from __future__ import annotations

import pytest

from tubekit.exceptions import ConfigError
from tubekit.settings import ControllerSettings, Disturbance, Heading, Obstacle, RegionSettings

ERRORS = [
    (lambda: Obstacle((0.0, 0.0, 0.0), -1.0), r"obstacle\.radius: expected a number > 0"),
    (lambda: Obstacle((0.0, 0.0, 0.0), 0.0), r"obstacle\.radius"),
    (lambda: Disturbance(amplitude=(-0.1, 0.0, 0.0)), r"disturbance\.amplitude: expected three numbers >= 0"),
    (lambda: ControllerSettings(horizon_steps=0), r"controller\.horizon_steps: expected an integer >= 1"),
    (lambda: ControllerSettings(candidate="yes"), r"controller\.candidate: expected true or false"),
    (lambda: ControllerSettings(law="nope"), r"controller\.law"),
    (lambda: RegionSettings(e_o_max=1.0), r"region\.e_o_max: expected a number in \(0, 1\)"),
    (lambda: RegionSettings(heading="sideways"), r"region\.heading"),
]


@pytest.mark.parametrize("build, match", ERRORS)
def test_bad_settings_are_refused_naming_the_field(build, match):
    with pytest.raises(ConfigError, match=match):
        build()


def test_the_defaults_are_the_papers_and_the_candidate_is_on():
    c = ControllerSettings()
    assert (c.dt, c.horizon_steps, c.horizon) == (0.1, 8, pytest.approx(0.8)) and c.candidate is True
    assert RegionSettings().heading == Heading.TOWARD == "toward"
    assert Disturbance().current_bound == pytest.approx(0.1 * 2 ** 0.5)
