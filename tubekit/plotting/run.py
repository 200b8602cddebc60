"""What a figure reads of a run: :class:`PlottedRun` (``tubekit.SimulationResult`` satisfies it) and ``Run``.

The plotting role does not import the loop (``tests/test_architecture.py``): it types the run it draws by the
few members it reads, so ``SimulationResult.plot()`` can hand itself over without an import cycle.
"""

from __future__ import annotations

from typing import Any, Mapping, Protocol, runtime_checkable

import numpy as np

from tubekit.scenario import Scenario
from tubekit.tightening import Tightening

__all__ = ["PlottedRun", "Run", "label_of", "is_dynamic"]

#: One run as the figures take it: (label, columns), the columns as in ``trajectory.csv``.
Run = tuple[str, Mapping[str, np.ndarray]]


@runtime_checkable
class PlottedRun(Protocol):
    """The members of a run that :func:`tubekit.plotting.summary.plot_run` reads.

    Attributes
    ----------
    scenario : Scenario
        What was simulated.
    tightening : Tightening
        The sets the run used: its tiers, the position tube, the bounds of V̄, the derived sway and loop bounds.
    tube : bool
        True for the tube controller, False for the baseline (nominal MPC alone: nothing is promised).
    body : numpy.ndarray or None
        The dynamic plant's body velocities; None on the kinematic plant.
    """

    scenario: Scenario
    tightening: Tightening
    tube: bool
    body: np.ndarray | None

    @property
    def metrics(self) -> dict[str, Any]:
        """The run's metrics (``metrics.json``): ``tiers`` and ``outcome`` give the verdict."""
        ...

    def columns(self) -> dict[str, np.ndarray]:
        """The log as named columns (``trajectory.csv``)."""
        ...


def label_of(run: PlottedRun) -> str:
    """``"tube"`` or ``"baseline"``: the run's label on every figure."""
    return "tube" if run.tube else "baseline"


def is_dynamic(columns: Mapping[str, np.ndarray]) -> bool:
    """True when the columns are a dynamic-plant run's (body velocities and thrusts logged)."""
    return all(name in columns for name in ("u_b", "v_b", "w_b", "r_b", "X", "Z", "N"))
