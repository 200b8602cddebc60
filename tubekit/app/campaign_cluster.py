"""The cluster of ``tubekit campaign``: a :class:`distributed.Client` on an existing scheduler, or on a
LocalCluster on 127.0.0.1 whose worker processes are forked from one warm fork server (issue 23).

A spawned dask worker starts a fresh interpreter, imports ``distributed`` (~0.4 s), then, on its first
tasks, ``verify``, scipy, cvxpy and the loop (~1.3 s) and its first certificate's one-off parts (~0.6 s);
when it stops it finalises that interpreter (~1 s). Each worker pays all of it, and on a 2-core machine
two workers pay it on the cores the campaign needs. Here multiprocessing's fork server is started
(:func:`start_fork_server`) as soon as the campaign is validated; it imports
:mod:`tubekit.app.campaign_worker`, which certifies and simulates one short copy of the campaign's first
scenario (:func:`warm_scenario`: on the kinematic plant when the campaign's is dynamic), while the client
reads its stored certificates, imports what its tables and figures need and starts the scheduler. Every worker is a fork of that server (dask's
``distributed.worker.multiprocessing-method = "forkserver"``): imported and warm at birth, and it leaves
through ``os._exit``, so the cluster closes at once. Nothing a run computes depends on this: the rows
are those of spawned workers.

Signals: the fork server is started inside :func:`tubekit.app.exit_codes.children_ignore_interrupts`, so
it and every worker forked from it ignore SIGINT; Ctrl-C reaches the client alone, which stops the
workers (exit 130). The fork server ends with the client process (multiprocessing's own protocol).
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import logging
import multiprocessing
import os
from typing import Any, Iterator

from tubekit.app.campaign_worker import WARM_SCENARIO_ENV
from tubekit.app.exit_codes import children_ignore_interrupts
from tubekit.exceptions import ConfigError
from tubekit.scenario import Scenario

__all__ = ["open_client", "start_fork_server", "warm_scenario", "PRELOAD", "WARM_DURATION_S"]

#: The modules the fork server imports: the worker's machinery, then the campaign's side of it, warmed.
PRELOAD = ("distributed", "tubekit.app.campaign_worker")
#: Simulated seconds of the fork server's warm-up run (s).
WARM_DURATION_S = 1.0


def warm_scenario(scenario: Scenario) -> Scenario:
    """The fork server's warm-up copy of ``scenario``: :data:`WARM_DURATION_S` s long and, on the dynamic plant,
    on the kinematic one. The warm-up's certificate is discarded (the workers certify every design again), and a
    dynamic certificate's fixed point and backup design can take seconds, paid twice; the kinematic copy (with
    station keeping, which the kinematic plant takes) imports and runs the same ``verify``, cvxpy and loop code."""
    warm = scenario.with_changes(duration=WARM_DURATION_S)
    if warm.plant.dynamic:  # a backup law that commands sway needs the dynamic plant: the default law's copy
        warm = warm.with_changes(plant=dataclasses.replace(warm.plant, kind="kinematic", start="trimmed"),
                                 **{"controller.backup": "station_keeping"})
    return warm


def start_fork_server(scenario: Scenario | None) -> bool:
    """Start this process's fork server, unless it runs already, with :data:`PRELOAD` imported and
    :mod:`tubekit.app.campaign_worker` warmed on a :data:`WARM_DURATION_S` s copy of ``scenario`` (None:
    imports only). False, and nothing started, where the platform has no fork server (Windows): the
    workers are then spawned.

    The server inherits the environment at its start: dask's ``distributed.nanny.pre-spawn-environ``
    (one BLAS thread per worker, as spawned workers get; the Nanny sets it in this process too) and
    :data:`WARM_SCENARIO_ENV` (:func:`warm_scenario`), which is removed from this process again at once.
    """
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return False
    import dask
    from multiprocessing import forkserver

    os.environ.update({k: str(v) for k, v in dask.config.get("distributed.nanny.pre-spawn-environ", {}).items()})
    if scenario is not None:
        os.environ[WARM_SCENARIO_ENV] = json.dumps(warm_scenario(scenario).to_dict())
    try:
        multiprocessing.get_context("forkserver").set_forkserver_preload(list(PRELOAD))
        with children_ignore_interrupts():  # the server, hence every worker forked from it, ignores Ctrl-C
            forkserver.ensure_running()
    finally:
        os.environ.pop(WARM_SCENARIO_ENV, None)
    return True


@contextlib.contextmanager
def _scheduler_client(scheduler: str) -> Iterator[Any]:
    """A client of the existing scheduler ``scheduler`` (tcp://HOST:PORT or tls://...)."""
    from distributed import Client

    if not scheduler.startswith(("tcp://", "tls://")):
        raise ConfigError("--scheduler", "an address tcp://HOST:PORT", scheduler)
    try:
        client = Client(scheduler, timeout="15s")
    except (OSError, TimeoutError) as exc:
        raise ConfigError("--scheduler", "a reachable dask scheduler", scheduler, str(exc)) from None
    with client:
        yield client


@contextlib.contextmanager
def open_client(workers: int, scheduler: str | None) -> Iterator[Any]:
    """A :class:`distributed.Client`: on ``scheduler`` (tcp://HOST:PORT), else on a LocalCluster of
    ``workers`` single-threaded worker processes bound to 127.0.0.1 (dashboard on 127.0.0.1, a free port),
    forked from the fork server (:func:`start_fork_server`; started here, without a warm-up, if it is not
    running yet)."""
    if scheduler is not None:
        with _scheduler_client(scheduler) as client:
            yield client
        return
    import dask
    from distributed import Client, LocalCluster

    method = "forkserver" if start_fork_server(None) else dask.config.get("distributed.worker.multiprocessing-method")
    with dask.config.set({"distributed.worker.multiprocessing-method": method}):
        # Ctrl-C: the client stops the workers, no worker traceback. The workers' logs are silenced below
        # CRITICAL: on a loaded machine a worker's heartbeat can still fail against the closing scheduler and
        # distributed logs that at ERROR with a traceback; a run's own failure reaches the client as its error.
        with children_ignore_interrupts():
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                                   scheduler_port=0, dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL)
        with cluster, Client(cluster) as client:
            yield client
