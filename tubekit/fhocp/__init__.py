"""The finite-horizon optimal control problem (FHOCP) of Section V and its solvers.

Modules, from the contract outwards:

* :mod:`~tubekit.fhocp.result` — :class:`FhocpResult`, the :class:`Status` enum,
  :class:`FallbackWarning` and the warm-start shift: what every backend returns and shares;
* :mod:`~tubekit.fhocp.nlp` — the discretised nonlinear program (:class:`FhocpNlp`):
  exact step, rollout, obstacle selection, the input box [v_min, v_max], evaluation;
* :mod:`~tubekit.fhocp.linearisation` — the first-order models of its step and bearing error (the SCP's data);
* :mod:`~tubekit.fhocp.convex` — the DPP cvxpy subproblem of one SCP iteration;
* :mod:`~tubekit.fhocp.fastpath` — the compiled parameter-to-data map, solved by a QP backend;
* :mod:`~tubekit.fhocp.qp` — the QP backends (Clarabel, PIQP through the relaxation wrapper, QOCO, QOCO generated
  for the pattern) by name;
* :mod:`~tubekit.fhocp.options` — :class:`ScpOptions`, the SCP solver's validated options;
* :mod:`~tubekit.fhocp.scp` — :class:`FHOCP`: SCP loop, trust region, fallback;
* :mod:`~tubekit.fhocp.ipopt` — :class:`IpoptFHOCP`, the CasADi + IPOPT peer (optional);
* :mod:`~tubekit.fhocp.registry` — the FHOCP backends by name (``"scp"``, ``"ipopt"``, ``"scp-piqp"``,
  ``"scp-qoco"``, ``"scp-qocogen"``):
  :func:`make_solver`.
"""

from __future__ import annotations

from tubekit.fhocp.convex import DEFAULT_CLARABEL_SETTINGS, REALTIME_CLARABEL_SETTINGS, ConvexSubproblem
from tubekit.fhocp.fastpath import CompiledConeProgram
from tubekit.fhocp.ipopt import IpoptFHOCP
from tubekit.fhocp.nlp import FhocpNlp, NlpEvaluation
from tubekit.fhocp.result import RESULT_STATUSES, FallbackWarning, FhocpResult, Status, shifted_plan
from tubekit.fhocp.options import ScpOptions
from tubekit.fhocp.registry import backends, get_backend, make_solver, register_backend
from tubekit.fhocp.scp import FHOCP, MODES, obstacle_slots

__all__ = ["FHOCP", "ScpOptions", "FhocpResult", "FallbackWarning", "MODES", "obstacle_slots",
           "DEFAULT_CLARABEL_SETTINGS", "REALTIME_CLARABEL_SETTINGS", "Status", "RESULT_STATUSES", "shifted_plan",
           "IpoptFHOCP", "FhocpNlp", "NlpEvaluation", "ConvexSubproblem", "CompiledConeProgram", "backends",
           "get_backend", "make_solver", "register_backend"]
