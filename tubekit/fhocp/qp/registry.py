"""The QP backends by name, registered by try-import: ``"clarabel"`` (default, cones), ``"piqp"`` (no cones),
``"qoco"`` (cones) and ``"qocogen"`` (cones; QOCO generated as C for the pattern, which also needs a C compiler).

Every built-in backend is registered when this module is imported, whether its package is installed
or not: a backend imports its package only in :meth:`QpBackend.load` (a try-import), so a missing
package makes it *unavailable* (``qp_backends()[name] is False``, and :func:`get_qp_backend` raises
:class:`~tubekit.exceptions.NotAvailableError` with the ``pip install`` hint), never an ImportError
here. :func:`make_qp_backend` turns a name (or an instance) into a backend for a cone program: one
that takes no cones is wrapped in :class:`~tubekit.fhocp.qp.relaxed.RelaxedQpBackend` with the
default cone backend as its fallback.
"""

from __future__ import annotations

from typing import Any, Mapping

from tubekit.exceptions import ConfigError
from tubekit.fhocp.qp.base import QpBackend
from tubekit.fhocp.qp.clarabel import ClarabelBackend
from tubekit.fhocp.qp.piqp import PiqpBackend
from tubekit.fhocp.qp.qoco import QocoBackend
from tubekit.fhocp.qp.qocogen import QocogenBackend
from tubekit.fhocp.qp.relaxed import RelaxedQpBackend

__all__ = ["DEFAULT_QP_BACKEND", "register_qp_backend", "qp_backends", "qp_backend_names", "get_qp_backend",
           "make_qp_backend"]

#: The backend of the SCP subproblems unless ``ScpOptions.qp_solver`` names another.
DEFAULT_QP_BACKEND = "clarabel"

_QP_BACKENDS: dict[str, type[QpBackend]] = {}


def register_qp_backend(backend: type[QpBackend], *, replace: bool = False) -> None:
    """Register the :class:`QpBackend` subclass ``backend`` under ``backend.name``.

    Raises
    ------
    ConfigError
        Not a :class:`QpBackend` subclass, an empty name, a non-bool ``takes_cones``, or a taken name
        without ``replace``.
    """
    if not isinstance(backend, type) or not issubclass(backend, QpBackend):
        raise ConfigError("backend", "a subclass of tubekit.fhocp.qp.base.QpBackend", backend)
    if not isinstance(backend.name, str) or not backend.name:
        raise ConfigError("backend.name", "a non-empty QP backend name", backend.name)
    if not isinstance(backend.takes_cones, bool):
        raise ConfigError("backend.takes_cones", "True or False", backend.takes_cones)
    if backend.name in _QP_BACKENDS and not replace:
        raise ConfigError("backend.name", f"a name not yet registered (taken: {qp_backend_names()}), "
                          "or replace=True", backend.name)
    _QP_BACKENDS[backend.name] = backend


def qp_backends() -> dict[str, bool]:
    """Every registered backend name -> whether its package can be imported (a try-import), in registration order."""
    return {name: cls.available() for name, cls in _QP_BACKENDS.items()}


def qp_backend_names() -> tuple[str, ...]:
    """The registered backend names, in registration order (no package is imported)."""
    return tuple(_QP_BACKENDS)


def get_qp_backend(name: str, field: str = "qp_solver") -> type[QpBackend]:
    """The backend class registered as ``name``.

    Raises
    ------
    ConfigError
        ``name`` is not registered (``field`` names the setting; the message lists the names).
    NotAvailableError
        Its package is missing (the message says what to ``pip install``).
    """
    cls = _QP_BACKENDS.get(name) if isinstance(name, str) else None
    if cls is None:
        raise ConfigError(field, f"one of the QP backends {qp_backend_names()}", name)
    cls.load()
    return cls


def make_qp_backend(backend: str | QpBackend = DEFAULT_QP_BACKEND,
                    settings: Mapping[str, Mapping[str, Any] | None] | None = None, *,
                    field: str = "qp_solver") -> QpBackend:
    """A backend ready for a cone program: ``backend`` itself, or the relaxation wrapper around it.

    Parameters
    ----------
    backend : str or QpBackend
        A registered name (built with its settings) or a backend instance (used as it is).
    settings : mapping, optional
        Per backend name, that backend's setting overrides, e.g. ``{"clarabel": {"tol_feas": 1e-7}}``;
        they reach the named backend and the default cone backend alike.
    field : str
        The setting that named ``backend`` (for the error message).

    Raises
    ------
    ConfigError, NotAvailableError
        As :func:`get_qp_backend`; a ``backend`` that is neither a name nor a :class:`QpBackend`.
    """
    per = dict(settings or {})
    if isinstance(backend, str):
        backend = get_qp_backend(backend, field)(per.get(backend))
    elif not isinstance(backend, QpBackend):
        raise ConfigError(field, "a QP backend name or a tubekit.fhocp.qp.base.QpBackend", backend)
    if backend.takes_cones:
        return backend
    return RelaxedQpBackend(backend, get_qp_backend(DEFAULT_QP_BACKEND, field)(per.get(DEFAULT_QP_BACKEND)))


for _builtin in (ClarabelBackend, PiqpBackend, QocoBackend, QocogenBackend):
    register_qp_backend(_builtin)
