"""The application layer: the only code that parses arguments, plots, writes result files or imports verify.

* :mod:`tubekit.app.cli` — the ``tubekit`` console script (one parser, every subcommand);
* :mod:`tubekit.app.study` — the closed-loop study of ``reproduce`` / ``simulate``
  (certify → tube run + baseline → metrics → files);
* :mod:`tubekit.app.plots` — every figure (a run's, an envelope's).

Nothing here is imported by ``import tubekit``; import the submodule you need.
"""

__all__: list[str] = []
