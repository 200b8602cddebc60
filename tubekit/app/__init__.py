"""The application layer: the only code that parses arguments, plots, writes result files or imports verify.

* :mod:`tubekit.app.cli` — the ``tubekit`` console script (one parser, every subcommand), with the
  subcommands in :mod:`tubekit.app.commands_study` and :mod:`tubekit.app.commands_verify`, the exit
  codes by error type in :mod:`tubekit.app.exit_codes` and the output-path / ``--json`` policy in
  :mod:`tubekit.app.output`;
* :mod:`tubekit.app.certified` — certify (or take a given certificate): the tightening a run uses;
* :mod:`tubekit.app.study` — the closed-loop study of ``reproduce`` / ``simulate``
  (certify → tube run + baseline with :func:`tubekit.loop.pipeline.certified_run` → files; a
  :class:`~tubekit.app.study.StudyResult`), :mod:`tubekit.app.dynamic_study` its dynamic-plant part,
  :mod:`tubekit.app.campaign` many runs on dask;
* :mod:`tubekit.app.plots` — every figure file (a run's are drawn by :mod:`tubekit.plotting`, ``run.plot()``; an envelope's);
* :mod:`tubekit.app.animate` — the animated top view (``--animate``).

Nothing here is imported by ``import tubekit``; import the submodule you need.
"""

__all__ = ["QUICK_S"]

#: Simulated seconds of ``--quick`` (here so the parser needs no study import).
QUICK_S = 10.0
