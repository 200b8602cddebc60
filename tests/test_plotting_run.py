"""tubekit.plotting.run: a SimulationResult is a PlottedRun (the plotting role types it without importing the
loop); the label and the dynamic test of a run's columns."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from tubekit.loop.result import SimulationResult
from tubekit.plotting.run import PlottedRun, is_dynamic, label_of


def test_the_protocol_names_only_what_a_simulation_result_has():
    fields = set(SimulationResult.__dataclass_fields__)
    assert {"scenario", "tightening", "tube", "body"} <= fields
    assert isinstance(getattr(SimulationResult, "metrics"), property) and callable(SimulationResult.columns)
    fake = SimpleNamespace(scenario=None, tightening=None, tube=True, body=None, metrics={}, columns=dict)
    assert isinstance(fake, PlottedRun) and not isinstance({"x": np.zeros(2)}, PlottedRun)


def test_label_and_dynamic_columns():
    assert label_of(SimpleNamespace(tube=True)) == "tube" and label_of(SimpleNamespace(tube=False)) == "baseline"
    kinematic = {"t": np.zeros(2), "x": np.zeros(2)}
    dynamic = {**kinematic, **{k: np.zeros(2) for k in ("u_b", "v_b", "w_b", "r_b", "X", "Z", "N")}}
    assert not is_dynamic(kinematic) and is_dynamic(dynamic)
