"""A study: the velocity loop's gain from a command rate to its error by an invariant ellipsoid (S-procedure).

Usage::

    python benchmarks/loop_rate_gain.py

Beside ``benchmarks/loop_ldi.py`` (whose jump bound uses the decay rate of a common Lyapunov function): for each
channel of the BlueROV2 Heavy over four coefficient boxes, the smallest γ with |e| <= γ ρ for a command rate
|ẏ*| <= ρ, from the LMIs [[A_iᵀP + PA_i + αP, P b_j], [b_jᵀP, −α]] ⪯ 0 at every vertex matrix A_i and every
corner b_j of the rate's input column (the same vertex sets as the LDI study), minimising cᵀP⁻¹c, over a grid of α.
Then V = xᵀPx <= ρ² for all time from rest, so |e| <= √(cᵀP⁻¹c) ρ. **Floats only, not proved**: what the bound
would be, to compare with the decay-rate bound and the small-gain one. About 10–40 s of SDPs per channel.
"""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path
from typing import Sequence

import numpy as np

from verify.kernel.intervals import upper
from verify.theorem.design import hull_sway_bound
from verify.vehicle.loop_data import loop_data_of

sys.path.insert(0, str(Path(__file__).resolve().parent))
import loop_ldi as study  # noqa: E402 - the LDI study's vertex sets, the same boxes

__all__ = ["ALPHAS", "ellipsoid_gain", "channel_gain", "main"]

#: The S-procedure's decay multipliers α (1/s) tried.
ALPHAS = (0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0)


def ellipsoid_gain(mats: Sequence[np.ndarray], columns: Sequence[np.ndarray], output: np.ndarray,
                   alphas: Sequence[float] = ALPHAS) -> float:
    """min over α of √(cᵀP⁻¹c) subject to the invariant-ellipsoid LMIs at every (A_i, b_j) (inf if none solves)."""
    import cvxpy as cp
    n, best = len(output), math.inf
    for alpha in alphas:
        p, g = cp.Variable((n, n), symmetric=True), cp.Variable()
        cons = [p >> 1e-9 * np.eye(n)]
        for a in mats:
            for b in columns:
                pb = cp.reshape(p @ b, (n, 1), order="C")
                cons.append(cp.bmat([[a.T @ p + p @ a + alpha * p, pb], [pb.T, -alpha * np.ones((1, 1))]]) << 0)
        cons.append(cp.bmat([[cp.reshape(g, (1, 1), order="C"), output[None, :]], [output[:, None], p]]) >> 0)
        problem = cp.Problem(cp.Minimize(g), cons)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                problem.solve(solver="CLARABEL")
            except cp.error.SolverError:
                continue
        if problem.status == cp.OPTIMAL and g.value is not None and _holds(p.value, mats, columns, alpha):
            best = min(best, math.sqrt(float(g.value)))
    return best


def _holds(p: np.ndarray | None, mats: Sequence[np.ndarray], columns: Sequence[np.ndarray], alpha: float,
           tol: float = 1e-7) -> bool:
    """The solver's P checked in floats: positive definite and every block, scaled by P's diagonal, with its largest
    eigenvalue <= tol x its size (a solver may call solved a problem whose only solutions sit on its tolerance)."""
    if p is None or not np.all(np.isfinite(p)) or np.linalg.eigvalsh(p).min() <= 0:
        return False
    scale = np.diag(np.append(1.0 / np.sqrt(np.diag(p)), 1.0))   # congruence: P's own scale, not the solver's
    for a in mats:
        for b in columns:
            pb = (p @ b)[:, None]
            block = scale @ np.block([[a.T @ p + p @ a + alpha * p, pb], [pb.T, -alpha * np.ones((1, 1))]]) @ scale
            if np.linalg.eigvalsh(block).max() > tol * max(1.0, np.abs(block).max()):
                return False
    return True


def channel_gain(params, channel: int, box: Sequence[float] = (0.44, 0.33, 0.33), tick: float = 0.01) -> float:
    """γ (s) of ``channel`` over the velocity box ``box`` and the vehicle's coefficient box (the LDI's vertex sets)."""
    loop = loop_data_of(params, (0.4, 0.3, 0.3), tick, 10)
    data = study._channel_data(params, box, upper(hull_sway_bound(params, box[0], box[2])), channel, loop.k_p,
                               loop.k_i, loop.lag, tick)
    mats = [study._floats(a) for a in study.vertex_matrices(data.k_p, data.k_i, data.lag, data.m_hat, data.pairs,
                                                            data.inv_mass)]
    m_hat = float(data.m_hat.mid())
    columns = [np.array([data.k_p, (p[0] - p[1]) / m_hat, -p[1] / m_hat]) for p in data.pairs]
    return ellipsoid_gain(mats, columns, np.array([1.0 / data.k_p, 0.0, 0.0]))


def main() -> int:
    print("sup|e| per unit command rate (s) by an invariant ellipsoid, u / w / r (floats, not proved); "
          "V = (0.4, 0.3, 0.3) + 10 %")
    for label, params in study._boxes():
        print(f"  {label:22s}", " / ".join(f"{channel_gain(params, c):.3f}" for c in range(3)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
