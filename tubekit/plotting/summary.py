"""The figure of one run, behind ``SimulationResult.plot()``: a panel set with the verdict in its title.

``kind="summary"`` (the default) is the top view (the target's end marked) beside the errors, the inputs and,
for a run on the dynamic plant, the thrust against its limits; the other kinds are the single figures the app
writes (:data:`KINDS`). The suptitle carries the verdict (:func:`tubekit.plotting.titles.run_verdict`).
"""

from __future__ import annotations

from typing import Callable, Sequence

from matplotlib.figure import Figure

from tubekit.exceptions import ConfigError
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening
from tubekit.plotting.clearance import clearance_figure
from tubekit.plotting.deviation import rho_figure
from tubekit.plotting.dynamic import draw_thrust, dynamic_figure
from tubekit.plotting.framing import end_time
from tubekit.plotting.run import PlottedRun, Run, is_dynamic, label_of
from tubekit.plotting.series import draw_errors, draw_inputs, errors_figure, inputs_figure
from tubekit.plotting.style import LEGEND_OUTSIDE
from tubekit.plotting.titles import run_verdict, title_lines
from tubekit.plotting.top_view import draw_top_view, top_view
from tubekit.plotting.view_3d import view_3d

__all__ = ["plot_run", "summary_figure", "KINDS", "Figure"]

Builder = Callable[[Scenario, Sequence[Run], Tightening | None], Figure]


def summary_figure(scenario: Scenario, runs: Sequence[Run], tightening: Tightening | None = None) -> Figure:
    """The top view beside e_d, e_z, e_o, u, w, r and, when the first run is a dynamic plant's, its thrust
    against its limits (one shared time axis)."""
    dynamic = bool(runs) and is_dynamic(runs[0][1])
    rows = 7 if dynamic else 6
    fig = Figure(figsize=(15.0, 1.3 * rows + 1.4), layout="constrained")
    grid = fig.add_gridspec(rows, 2, width_ratios=(1.1, 1.0))
    view = fig.add_subplot(grid[:, 0])
    draw_top_view(view, scenario, runs, tightening=tightening)
    view.set_title("top view")
    view.legend(loc="upper center", bbox_to_anchor=(0.5, -0.07), ncol=2, fontsize=6.5, frameon=False)
    first = fig.add_subplot(grid[0, 1])
    axes = [first] + [fig.add_subplot(grid[k, 1], sharex=first) for k in range(1, rows)]
    draw_errors(axes[:3], scenario, runs, legend=False)
    draw_inputs(axes[3:6], scenario, runs, tightening=tightening, legend=False)
    if dynamic:
        draw_thrust(axes[6], scenario, runs[0][1])
        axes[6].set_title("")
        axes[6].grid(alpha=0.3)
        axes[6].legend(fontsize=6.5, ncol=4, loc="upper right")
    axes[0].legend(**{**LEGEND_OUTSIDE, "fontsize": 6.5})
    axes[3].legend(**{**LEGEND_OUTSIDE, "fontsize": 6.5})
    for ax in axes[:-1]:
        ax.tick_params(labelbottom=False)
    axes[-1].set_xlabel("t (s)")
    return fig


def _one_run(builder: Callable[[Scenario, Sequence[Run]], Figure]) -> Builder:
    return lambda scenario, runs, tightening: builder(scenario, runs)


def _dynamic(scenario: Scenario, runs: Sequence[Run], tightening: Tightening | None) -> Figure:
    if not runs or not is_dynamic(runs[0][1]):
        raise ConfigError("kind", "'dynamic' only for a run on the dynamic plant ([plant] kind = \"dynamic\")",
                          "dynamic")
    return dynamic_figure(scenario, runs[0], tightening)


#: The figures ``plot(kind=...)`` draws, by kind.
KINDS: dict[str, Builder] = {
    "summary": summary_figure,
    "top_view": lambda scenario, runs, tightening: top_view(scenario, runs, tightening=tightening),
    "errors": _one_run(errors_figure),
    "inputs": lambda scenario, runs, tightening: inputs_figure(scenario, runs, tightening=tightening),
    "deviation": lambda scenario, runs, tightening: rho_figure(
        runs, None if tightening is None else tightening.tube, tightening is not None and tightening.tiers.tracking),
    "clearance": _one_run(clearance_figure),
    "view_3d": _one_run(view_3d),
    "dynamic": _dynamic,
}


def plot_run(run: PlottedRun, kind: str = "summary") -> Figure:
    """The figure of one run (a :class:`tubekit.SimulationResult`), the verdict in its title.

    Parameters
    ----------
    run : PlottedRun
        The run; a baseline run (``run.tube`` False) is drawn without a tube and titled
        "baseline: nothing is promised".
    kind : str
        One of :data:`KINDS`: ``"summary"`` (top view, errors, inputs, and the thrust of a dynamic-plant run),
        ``"top_view"``, ``"errors"``, ``"inputs"``, ``"deviation"``, ``"clearance"``, ``"view_3d"``, or
        ``"dynamic"`` (thrust, loop error, sway and clearance of a dynamic-plant run).

    Returns
    -------
    matplotlib.figure.Figure
        Not shown and not saved: ``fig.savefig("run.png")``.

    Raises
    ------
    ConfigError
        ``run`` is not a run, ``kind`` is not one of :data:`KINDS`, or ``"dynamic"`` for a kinematic run.
    """
    if not isinstance(run, PlottedRun):
        raise ConfigError("run", "a tubekit.SimulationResult", type(run).__name__)
    if kind not in KINDS:
        raise ConfigError("kind", f"one of {', '.join(KINDS)}", kind)
    label = label_of(run)
    runs = [(label, run.columns())]
    fig = KINDS[kind](run.scenario, runs, run.tightening if run.tube else None)
    head = fig.get_suptitle() or f"{run.scenario.name}: {label} run, {end_time(run.scenario, runs):g} s"
    fig.suptitle(title_lines(head, run_verdict(run)), fontsize=10)
    return fig
