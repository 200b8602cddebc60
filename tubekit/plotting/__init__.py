"""The figures of a run, drawn from its logged columns (``trajectory.csv``) and its scenario: the plotting role.

With :mod:`tubekit.app`, the only code that imports matplotlib. It imports only the configuration
(:mod:`tubekit.scenario`, :mod:`tubekit.tightening`, :mod:`tubekit.tiers`), the model and the ground: never the
loop, the solver, the plant, the app or verify (``tests/test_architecture.py``). So
``SimulationResult.plot()`` imports it on use without an import cycle, the app writes the same figures into
files (:mod:`tubekit.app.plots`), and ``import tubekit`` loads no matplotlib (nothing imports this package when
``tubekit`` is imported; this ``__init__`` imports none of its modules).

* :mod:`~tubekit.plotting.run` -- what a figure reads of a run (:class:`~tubekit.plotting.run.PlottedRun`) and
  ``Run`` = (label, columns);
* :mod:`~tubekit.plotting.style` -- run styles, the backup's shading, time ticks, distances in mm or m;
* :mod:`~tubekit.plotting.titles` -- the verdict line: the tiers and what happened to them on the run;
* :mod:`~tubekit.plotting.framing` -- the top view's frame: a zoom on the path, obstacles and the sensing range
  only when they fit;
* :mod:`~tubekit.plotting.top_view` -- Fig. 2 (path, tube, time ticks, the target at the start and at the end),
  with :mod:`~tubekit.plotting.side_view` beside it;
* :mod:`~tubekit.plotting.series` -- Figs. 3 and 4 (errors, inputs); :mod:`~tubekit.plotting.deviation` -- the
  deviation against the tube box; :mod:`~tubekit.plotting.clearance` -- the clearance;
* :mod:`~tubekit.plotting.view_3d` -- the 3-D view;
* :mod:`~tubekit.plotting.dynamic` -- the dynamic plant's panel set (thrust, loop error, sway, clearance);
* :mod:`~tubekit.plotting.summary` -- :func:`~tubekit.plotting.summary.plot_run`, behind ``SimulationResult.plot()``.

Every function returns a :class:`matplotlib.figure.Figure` (Agg canvas): no pyplot state, no window, never
``show()``.
"""

__all__: list[str] = []
