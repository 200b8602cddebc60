"""tubekit.fhocp.qp.registry: QP backends by name, registered by try-import, a missing package named."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from tubekit import ConfigError, NotAvailableError
from tubekit.fhocp import FHOCP, ScpOptions
from tubekit.fhocp.convex import ConvexSubproblem
from tubekit.fhocp.qp import registry
from tubekit.fhocp.qp.base import QpBackend
from tubekit.fhocp.qp.clarabel import ClarabelBackend
from tubekit.fhocp.qp.piqp import PiqpBackend
from tubekit.fhocp.qp.registry import (get_qp_backend, make_qp_backend, qp_backend_names, qp_backends,
                                       register_qp_backend)
from tubekit.fhocp.qp.relaxed import RelaxedQpBackend
from tubekit.fhocp.registry import make_solver

from .fhocp_cases import SC, STATES, tightening


@pytest.fixture
def private_registry(monkeypatch):
    """Registrations made by a test stay in that test."""
    monkeypatch.setattr(registry, "_QP_BACKENDS", dict(registry._QP_BACKENDS))


@pytest.fixture
def no_piqp(monkeypatch):
    """PIQP missing: ``import piqp`` raises ImportError (``sys.modules[name] = None``)."""
    monkeypatch.setitem(sys.modules, "piqp", None)


class Delegate(ClarabelBackend):
    """A registered backend of one's own (Clarabel under another name)."""

    name = "mine"


class NoCones(PiqpBackend):
    """A backend without cones under another name."""

    name = "mine-qp"


def _named(name, takes_cones=True):
    return type("Named", (Delegate,), {"name": name, "takes_cones": takes_cones})


@pytest.mark.parametrize("call, message", [
    (lambda: get_qp_backend("osqp"), r"^qp_solver: expected one of the QP backends \('clarabel', 'piqp'"),
    (lambda: get_qp_backend(3), r"^qp_solver: expected one of the QP backends"),
    (lambda: get_qp_backend("osqp", "backend"), r"^backend: expected one of the QP backends"),
    (lambda: make_qp_backend("osqp"), r"^qp_solver: expected one of the QP backends .*received 'osqp'"),
    (lambda: make_qp_backend(3.0), r"^qp_solver: expected a QP backend name or a .*QpBackend"),
    (lambda: register_qp_backend(object), r"^backend: expected a subclass of .*QpBackend"),
    (lambda: register_qp_backend(Delegate()), r"^backend: expected a subclass"),
    (lambda: register_qp_backend(_named("")), r"^backend\.name: expected a non-empty QP backend name"),
    (lambda: register_qp_backend(_named("x", takes_cones=1)), r"^backend\.takes_cones: expected True or False"),
    (lambda: register_qp_backend(_named("clarabel")), r"^backend\.name: expected a name not yet registered"),
    (lambda: ScpOptions(qp_solver="osqp"), r"^qp_solver: expected one of the QP backends \('clarabel', 'piqp'"),
    (lambda: ScpOptions(qp_solver=None), r"^qp_solver: expected one of the QP backends"),
    (lambda: ScpOptions(qp_solver="piqp", fast_path=False), r"^qp_solver: expected 'clarabel' when fast_path=False"),
    (lambda: ClarabelBackend(["tol_feas"]), r"^clarabel settings: expected a mapping"),
], ids=["unknown", "not-a-str", "field", "make-unknown", "make-not-a-backend", "register-not-a-class",
        "register-an-instance", "register-empty-name", "register-takes-cones", "register-taken",
        "options-unknown", "options-none", "options-slow-path", "settings"])
def test_the_error_table(private_registry, call, message):
    with pytest.raises(ConfigError, match=message):
        call()


def test_the_builtin_backends_and_their_declarations():
    assert qp_backend_names()[:2] == ("clarabel", "piqp") == tuple(qp_backends())[:2]
    assert qp_backends()["clarabel"] is True
    assert get_qp_backend("clarabel") is ClarabelBackend and ClarabelBackend.takes_cones
    assert PiqpBackend.takes_cones is False
    assert registry.DEFAULT_QP_BACKEND == "clarabel" == ScpOptions().qp_solver


def test_a_missing_package_is_listed_as_unavailable_and_named_on_use(no_piqp):
    assert qp_backends()["piqp"] is False and "piqp" in qp_backend_names()
    assert ScpOptions(qp_solver="piqp").qp_solver == "piqp"  # a name, checked when the solver is built
    with pytest.raises(NotAvailableError, match=r"QP backend 'piqp' needs piqp: pip install piqp"):
        get_qp_backend("piqp")
    with pytest.raises(NotAvailableError, match="pip install piqp"):
        PiqpBackend()
    with pytest.raises(NotAvailableError, match="pip install piqp"):
        FHOCP(SC, tightening(), options=ScpOptions(qp_solver="piqp"))


def test_without_piqp_the_fhocp_backend_says_how_to_install(no_piqp):
    with pytest.raises(NotAvailableError, match="pip install piqp"):
        make_solver(SC, tightening(), "scp-piqp")


def test_make_qp_backend_wraps_a_backend_without_cones_and_routes_the_settings():
    pytest.importorskip("piqp")
    clarabel = make_qp_backend("clarabel", {"clarabel": {"tol_feas": 1e-6}, "piqp": {"max_iter": 7}})
    assert type(clarabel) is ClarabelBackend and clarabel.settings == {"tol_feas": 1e-6}
    relaxed = make_qp_backend("piqp", {"clarabel": {"tol_feas": 1e-6}, "piqp": {"max_iter": 7}})
    assert isinstance(relaxed, RelaxedQpBackend) and relaxed.takes_cones
    assert isinstance(relaxed.qp, PiqpBackend) and relaxed.qp.settings["max_iter"] == 7
    assert isinstance(relaxed.cones, ClarabelBackend) and relaxed.cones.settings == {"tol_feas": 1e-6}
    mine = ClarabelBackend()
    assert make_qp_backend(mine) is mine  # an instance is used as it is


def test_a_registered_backend_is_selected_by_name(private_registry):
    register_qp_backend(Delegate)
    assert qp_backend_names()[-1] == "mine" and qp_backends()["mine"] is True
    tg = tightening()
    ref, mine = FHOCP(SC, tg, mode="realtime"), FHOCP(SC, tg, mode="realtime", options=ScpOptions(qp_solver="mine"))
    assert type(mine.subproblem.compiled.backend) is Delegate
    for t, s in STATES[:3]:
        a, b = ref.solve(t, np.array(s), SC.obstacles), mine.solve(t, np.array(s), SC.obstacles)
        # Clarabel under another name (without the SCP's Clarabel settings, which go to "clarabel" only: the
        # real-time mode's 1e-6 against Clarabel's own 1e-8)
        np.testing.assert_allclose(b.inputs, a.inputs, atol=1e-4)
    register_qp_backend(_named("mine"), replace=True)
    assert get_qp_backend("mine").__name__ == "Named"


def test_a_registered_backend_without_cones_is_wrapped(private_registry):
    pytest.importorskip("piqp")
    register_qp_backend(NoCones)
    backend = make_qp_backend("mine-qp")
    assert isinstance(backend, RelaxedQpBackend) and isinstance(backend.qp, NoCones)


def test_the_subproblem_takes_the_backend_in_its_constructor():
    tg = tightening()
    solver = FHOCP(SC, tg)
    nlp, ref = solver.nlp, solver.nlp.reference(SC.trajectory, 0.0)
    s0 = np.asarray(SC.initial_state, dtype=float)
    mine = ClarabelBackend({"tol_feas": 1e-8})
    sub = ConvexSubproblem(nlp, 1, s0, ref, 0.5, qp_backend=mine)
    assert sub.compiled.backend is mine
    with pytest.raises(ConfigError, match=r"^qp_backend: expected 'clarabel' when fast_path=False"):
        ConvexSubproblem(nlp, 1, s0, ref, 0.5, fast_path=False, qp_backend=mine)
    assert isinstance(ConvexSubproblem(nlp, 1, s0, ref, 0.5).compiled.backend, QpBackend)
