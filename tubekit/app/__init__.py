"""The application layer: the only code that parses arguments, plots, writes result files or imports verify.

* :mod:`tubekit.app.cli` — the ``tubekit`` console script (one parser, every subcommand);
* :mod:`tubekit.app.study` — the closed-loop study of ``reproduce`` / ``simulate``
  (certify → tube run + baseline → metrics → files);
* :mod:`tubekit.app.plots` — every figure (a run's, an envelope's);
* :mod:`tubekit.app.animate` — the animated top view (``--animate``).

Nothing here is imported by ``import tubekit``; import the submodule you need.
"""

__all__ = ["QUICK_S"]

#: Simulated seconds of ``--quick`` (here so the parser needs no study import).
QUICK_S = 10.0
