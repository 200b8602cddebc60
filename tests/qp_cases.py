"""Small cone programs with known answers, shared by the QP backends' tests."""

from __future__ import annotations

import numpy as np

from tubekit.fhocp.qp.base import ConeDims, ConeProgramData

__all__ = ["small_qp", "disc"]


def small_qp(center) -> ConeProgramData:
    """min 1/2 |x - c|^2 s.t. x_0 = x_1 (zero row), x_0 <= 1 and x_1 >= -1 (nonnegative rows)."""
    A = np.array([[1.0, -1.0], [1.0, 0.0], [0.0, -1.0]])
    return ConeProgramData.from_matrices(np.eye(2), -np.asarray(center, dtype=float), A, [0.0, 1.0, 1.0],
                                         ConeDims(zero=1, nonneg=2), offset=0.5 * float(np.dot(center, center)))


def disc(radius: float) -> ConeProgramData:
    """min x_0 + x_1 s.t. ||x|| <= radius (one second-order cone, no zero row): x = -radius (1, 1)/sqrt 2."""
    A = np.array([[0.0, 0.0], [-1.0, 0.0], [0.0, -1.0]])
    return ConeProgramData.from_matrices(np.zeros((2, 2)), np.ones(2), A, [radius, 0.0, 0.0], ConeDims(soc=(3,)))
