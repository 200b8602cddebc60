"""The fork server's warm-up (tubekit.app.campaign_worker): it runs only on a scenario handed over in its
environment, and a warm-up that fails is skipped, never raised (a fork server that raised would start
no worker)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from tubekit.app import campaign_worker
from tubekit.app.campaign_worker import WARM_SCENARIO_ENV, warm
from tubekit.scenario import paper_scenario


@pytest.mark.parametrize("text", [None, "", "not json", json.dumps({"duration": -1.0})])
def test_nothing_to_warm_on_or_a_failed_warm_up_is_skipped(text):
    assert warm(text) is None


def test_importing_it_without_the_variable_warms_nothing():
    assert WARM_SCENARIO_ENV not in os.environ and campaign_worker.WARMED_S is None


def test_a_fresh_import_with_the_variable_certifies_and_runs_the_scenario_once():
    """In a new interpreter (as in the fork server): the warm-up ran, the loop and verify are loaded."""
    scenario = json.dumps(paper_scenario().with_changes(duration=0.5).to_dict())
    probe = ("import sys, tubekit.app.campaign_worker as w; "
             "print(w.WARMED_S is not None, 'tubekit.loop.pipeline' in sys.modules, 'verify.certificate.certify' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120,
                          env={**os.environ, WARM_SCENARIO_ENV: scenario})
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["True", "True", "True"]
