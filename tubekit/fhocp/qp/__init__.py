"""The QP-backend seam of the SCP solver: one module per backend, a registry, a relaxation wrapper.

* :mod:`~tubekit.fhocp.qp.base` — the contract: :class:`ConeProgramData` (the compiled subproblem's
  P, q, A, b and cones), :class:`ConeSolution`, the :class:`QpBackend` ABC (``name``, ``takes_cones``,
  ``available()``, ``solve``);
* :mod:`~tubekit.fhocp.qp.clarabel` — Clarabel, the default (takes second-order cones);
* :mod:`~tubekit.fhocp.qp.piqp` — PIQP (opt-in, no cones);
* :mod:`~tubekit.fhocp.qp.qoco` — QOCO (opt-in, takes second-order cones);
* :mod:`~tubekit.fhocp.qp.qocogen` — QOCO generated as C for the subproblem's pattern (opt-in, takes cones), built
  and cached by :mod:`~tubekit.fhocp.qp.generated`;
* :mod:`~tubekit.fhocp.qp.relaxed` — :class:`RelaxedQpBackend`: a backend without cones on the QP
  relaxation, its answer checked against the cones, else the cone backend;
* :mod:`~tubekit.fhocp.qp.registry` — :func:`register_qp_backend`, :func:`qp_backends`,
  :func:`qp_backend_names`, :func:`get_qp_backend`, :func:`make_qp_backend` (what
  ``ScpOptions(qp_solver=...)`` goes through).

Importing this package imports neither Clarabel, PIQP, QOCO nor qocogen: a backend imports its package when it is
built.
"""

from __future__ import annotations

from tubekit.fhocp.qp.base import ConeDims, ConeProgramData, ConeSolution, QpBackend
from tubekit.fhocp.qp.registry import (DEFAULT_QP_BACKEND, get_qp_backend, make_qp_backend, qp_backend_names,
                                       qp_backends, register_qp_backend)
from tubekit.fhocp.qp.relaxed import RelaxedQpBackend

__all__ = ["ConeDims", "ConeProgramData", "ConeSolution", "QpBackend", "RelaxedQpBackend", "DEFAULT_QP_BACKEND",
           "get_qp_backend", "make_qp_backend", "qp_backend_names", "qp_backends", "register_qp_backend"]
