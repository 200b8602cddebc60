"""The figures of a study, written as files: paper Figs. 2-4, the deviation against the tube box, a 3-D view,
the clearance and, for a run on the dynamic plant, its panel set (thrust, loop error, sway, clearance).

The drawing is :mod:`tubekit.plotting` (also behind ``SimulationResult.plot()``); this module chooses the files,
adds the tier line to each title and writes the PNGs. Every figure is drawn from logged columns (as from
``trajectory.csv``), so figures can be redrawn from the CSVs.
"""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

from matplotlib.figure import Figure

from tubekit.tightening import Tightening
from tubekit.scenario import Scenario
from tubekit.plotting.clearance import clearance_figure
from tubekit.plotting.deviation import rho_figure
from tubekit.plotting.dynamic import dynamic_figure
from tubekit.plotting.run import Run, is_dynamic
from tubekit.plotting.series import errors_figure, inputs_figure
from tubekit.plotting.summary import plot_run  # re-exported: its old home, named in tubekit.api's docs
from tubekit.plotting.titles import tier_title, title_lines  # re-exported: tubekit.app.tiers builds its title
from tubekit.plotting.top_view import top_view
from tubekit.plotting.view_3d import view_3d
from tubekit.app.plots_envelope import envelope_figure, plot_envelope  # re-exported: their old home (tutorial 08)

__all__ = [
    "plot_all",
    "save_figure",
    "FIGURE_FILES",
    "DYNAMIC_FIGURE",
    "plot_run",
    "tier_title",
    "envelope_figure",
    "plot_envelope",
]

#: File names written by :func:`plot_all` for every study.
FIGURE_FILES: tuple[str, ...] = ("fig2_top_view.png", "fig3_errors.png", "fig4_inputs.png", "rho.png",
                                 "view_3d.png", "clearance.png")
#: The file :func:`plot_all` adds when the first run is on the dynamic plant
#: (:func:`tubekit.plotting.dynamic.dynamic_figure`).
DYNAMIC_FIGURE = "dynamic_plant.png"


def save_figure(fig: Figure, path: str | Path, *, tiers: str | None = None, dpi: int = 110) -> Path:
    """Write ``fig`` to ``path`` (PNG), the tier line ``tiers`` (:func:`tier_title`) added below its title."""
    if tiers:
        head = fig.get_suptitle()
        fig.suptitle(title_lines(head, tiers, width=140 if fig.get_figwidth() > 11 else 110),
                     fontsize=9 if head else 10)
    path = Path(path)
    fig.savefig(path, dpi=dpi)
    return path


def plot_all(out_dir: str | Path, scenario: Scenario, runs: Sequence[Run], *, dpi: int = 110,
             tightening: Tightening | None = None, tiers: str | None = None) -> list[Path]:
    """Write every figure of :data:`FIGURE_FILES` into ``out_dir`` (and :data:`DYNAMIC_FIGURE` when the first run
    is on the dynamic plant); returns the paths.

    ``tightening`` (optional) adds the position tube to the top view, the bounds of V̄ to the inputs, the
    per-axis tube box to ``rho.png`` (each "certified" only when its tiers give tracking) and the derived bounds
    to the dynamic panel set; ``tiers`` (optional, :func:`tier_title`) is added as a title line to every figure.
    The first run's backup-active stretches are shaded on every time axis and marked on the top view.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    tracking = tightening is not None and tightening.tiers.tracking
    figs = [top_view(scenario, runs, tightening=tightening), errors_figure(scenario, runs),
            inputs_figure(scenario, runs, tightening=tightening),
            rho_figure(runs, None if tightening is None else tightening.tube, tracking),
            view_3d(scenario, runs), clearance_figure(scenario, runs)]
    names = list(FIGURE_FILES)
    if runs and is_dynamic(runs[0][1]):
        figs.append(dynamic_figure(scenario, runs[0], tightening))
        names.append(DYNAMIC_FIGURE)
    return [save_figure(fig, out / name, tiers=tiers, dpi=dpi) for name, fig in zip(names, figs)]
