"""The worker side of a campaign, imported and warmed once in the fork server of
:mod:`tubekit.app.campaign_cluster`, so that every worker forked from it starts warm (issue 23).

A fork server only imports its preload modules, so importing this module runs :func:`warm`: when the
environment variable :data:`WARM_SCENARIO_ENV` holds a scenario (JSON, set by
the client for the server alone), it is certified (:func:`tubekit.app.certified.issue_certificate`) and
simulated once (:func:`tubekit.app.campaign_task.simulate_task`): the imports of ``verify``, scipy, cvxpy and the
loop and the certificate's one-off parts are done here, once, instead of in every worker's first tasks.
The results are dropped. A warm-up that fails is skipped (the workers then do that work themselves): a
fork server that raised while importing would start no worker at all. After a warm-up the objects alive
are moved out of the garbage collector's reach (:func:`gc.freeze`): no worker's collections walk them
again, and the fork server, which ends with the client, leaves at once instead of collecting them.
"""

from __future__ import annotations

import gc
import json
import logging
import os
import time
import warnings

from tubekit.app.campaign_task import RunTask, simulate_task
from tubekit.app.certified import issue_certificate
from tubekit.scenario import scenario_from_dict

__all__ = ["warm", "WARMED_S", "WARM_SCENARIO_ENV"]

LOGGER = logging.getLogger(__name__)
#: Environment variable carrying, to the fork server only, the JSON of the scenario it warms up on.
WARM_SCENARIO_ENV = "TUBEKIT_CAMPAIGN_WARM_SCENARIO"


def warm(text: str | None) -> float | None:
    """Certify and simulate the scenario of JSON ``text`` once, results dropped; the seconds it took, or
    None when there was nothing to warm on or the warm-up failed (then logged at debug level)."""
    if not text:
        return None
    started = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scenario = scenario_from_dict(json.loads(text))
            simulate_task(RunTask(0, 0, scenario, None, 0), issue_certificate(scenario))
    except Exception as exc:  # noqa: BLE001  (an optimisation only: the workers redo everything)
        LOGGER.debug("campaign warm-up skipped: %s", exc)
        return None
    return time.perf_counter() - started


#: Seconds the warm-up took in this process (None: none ran).
WARMED_S = warm(os.environ.get(WARM_SCENARIO_ENV))
if WARMED_S is not None:
    gc.freeze()
