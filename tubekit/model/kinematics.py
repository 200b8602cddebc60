"""Underactuated AUV kinematics, eqs. (2) and (11) of the paper.

State ``x = [x, y, z, psi]`` (m, m, m, rad), input ``v = [u, w, r]`` (surge m/s,
heave m/s, yaw rate rad/s), disturbance ``omega = [omega_1, omega_2, omega_3]``
(m/s, inertial frame) = current ``delta`` + sway term ``g(x, v_sway)``.
The disturbance is evaluated (and the plant integrated) in :mod:`tubekit.plant.kinematic`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.validation import finite, nonnegative, positive

__all__ = [
    "InputLimits",
    "SwayModel",
    "nominal_kinematics",
    "kinematics",
    "sinc",
    "dsinc",
    "SINC_SERIES_THRESHOLD",
    "unicycle_step",
]


def _triple(field: str, value: object, expected: str, item: str,
            check: Callable[[str, object], float]) -> tuple[float, float, float]:
    """``value`` as three floats, each passed through ``check`` (``positive``, ``finite``); strings and booleans
    refused (ConfigError naming ``field`` or ``field[i]``, ``expected`` / ``item`` the expected texts)."""
    if isinstance(value, (str, bytes)) or not isinstance(value, (list, tuple, np.ndarray)) or len(value) != 3:
        raise ConfigError(field, expected, value)
    out = []
    for i, x in enumerate(value):
        if isinstance(x, (str, bytes, bool, np.bool_)) or not isinstance(x, (int, float, np.integer, np.floating)):
            raise ConfigError(f"{field}[{i}]", item, x)
        out.append(check(f"{field}[{i}]", x))
    return (out[0], out[1], out[2])


def _rate_triple(value: object) -> tuple[float, float, float]:
    """``limits.rate`` as three positive finite floats; strings and booleans refused (ConfigError)."""
    return _triple("limits.rate", value, "three numbers > 0 [rho_u, rho_w, rho_r] (m/s^2, m/s^2, rad/s^2)",
                   "a number > 0", positive)


def _command_triple(value: object) -> tuple[float, float, float]:
    """``limits.initial`` as three finite floats; strings and booleans refused (ConfigError)."""
    return _triple("limits.initial", value, "three numbers [u, w, r] (m/s, m/s, rad/s)", "a number", finite)


@dataclass(frozen=True)
class InputLimits:
    """Box input set V = {u_min <= u <= u_max, |w| <= w_max, |r| <= r_max}.

    Parameters
    ----------
    u_max, w_max : float
        Surge and heave speed limits (m/s).
    r_max : float
        Yaw-rate limit (rad/s).
    rate : (float, float, float) or None
        Command-rate limit [rho_u, rho_w, rho_r] (m/s^2, m/s^2, rad/s^2): every plan changes
        its command by at most J = rate * controller.dt per period (``tubekit.fhocp.rows``);
        None (default): no rate limit.
    u_min : float or None
        The smallest surge command (m/s), in [0, u_max): a vehicle that must keep moving (fins without
        authority at rest) never commands less. None (default): the symmetric box, u >= -u_max.
    initial : (float, float, float) or None
        With a rate limit, the command applied before t = 0 (m/s, m/s, rad/s), inside the box: the vehicle is
        already under way, and the first plan's first row lies within J of it. None (default): the box's point
        nearest rest (:attr:`start_command`).
    """

    u_max: float
    w_max: float
    r_max: float
    rate: tuple[float, float, float] | None = None
    u_min: float | None = None
    initial: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        for name in ("u_max", "w_max", "r_max"):
            object.__setattr__(self, name, positive(f"limits.{name}", getattr(self, name)))
        if self.rate is not None:
            object.__setattr__(self, "rate", _rate_triple(self.rate))
        if self.u_min is not None:
            floor = nonnegative("limits.u_min", self.u_min)
            if floor >= self.u_max:
                raise ConfigError("limits.u_min", f"a surge in [0, u_max = {self.u_max:g}) m/s", self.u_min)
            object.__setattr__(self, "u_min", floor)
        if self.initial is not None:
            if self.rate is None:
                raise ConfigError("limits.initial", "only with limits.rate (without a rate limit a plan's first row "
                                  "may be anywhere in V)", self.initial)
            start = _command_triple(self.initial)
            if not self.contains(np.array(start), tol=0.0):
                raise ConfigError("limits.initial", f"a command inside the box [{self.surge_floor:g}, {self.u_max:g}] x "
                                  f"[-{self.w_max:g}, {self.w_max:g}] x [-{self.r_max:g}, {self.r_max:g}]", self.initial)
            object.__setattr__(self, "initial", start)

    @property
    def start_command(self) -> np.ndarray:
        """(3,) the command before t = 0 (m/s, m/s, rad/s): ``initial``, else the box's point nearest rest
        (u_min, 0, 0) under a minimum surge, 0 otherwise."""
        if self.initial is not None:
            return np.array(self.initial, dtype=float)
        return np.clip(np.zeros(3), self.lower, self.vector)

    @property
    def surge_floor(self) -> float:
        """The smallest surge command (m/s): ``u_min``, or -u_max for the symmetric box."""
        return -self.u_max if self.u_min is None else self.u_min

    @property
    def lower(self) -> np.ndarray:
        """The box's lower corner ``[surge_floor, -w_max, -r_max]`` (m/s, m/s, rad/s)."""
        return np.array([self.surge_floor, -self.w_max, -self.r_max])

    def jump(self, dt: float) -> np.ndarray | None:
        """J = rate * ``dt`` (3,): the largest command change per period (None without a rate limit)."""
        return None if self.rate is None else np.asarray(self.rate, dtype=float) * float(dt)

    @property
    def vector(self) -> np.ndarray:
        """The limits as ``[u_max, w_max, r_max]``: the upper corner, and the largest |u|, |w|, |r| in V."""
        return np.array([self.u_max, self.w_max, self.r_max])

    @property
    def norm(self) -> float:
        """The paper's scalar bound V-bar = sqrt(u_max^2 + w_max^2 + r_max^2) (eq. Vbar)."""
        return float(np.linalg.norm(self.vector))

    def contains(self, v: np.ndarray, tol: float = 1e-9) -> bool:
        """True when every component of ``v`` is within its limits (plus ``tol``), the surge floor included."""
        v = np.asarray(v, dtype=float)
        return bool(np.all(np.abs(v) <= self.vector + tol) and np.all(v >= self.lower - tol))


@dataclass(frozen=True)
class SwayModel:
    """How the unactuated sway velocity v_s is generated (the paper leaves it open).

    ``v_s = gain * u * r + amplitude * sin(2 pi t / period)`` (no clip).
    ``gain * u * r`` is the steady-turn side-slip of a slender hull (sway
    proportional to centripetal acceleration); the sinusoid models wave-induced
    sway. Over V the model gives |v_s| <= gain u_max r_max + amplitude: that is
    gamma-bar (the paper's v-bar), derived by the verifier. ``bound`` is the bound
    the user *declares*; the certificate fails (condition ``sway_bound``) when it
    is below what the model produces, and every run checks the sway it applied.
    Evaluated by :meth:`tubekit.plant.kinematic.Plant.sway_velocity`.

    Parameters
    ----------
    gain : float
        Side-slip coefficient (s); v_s contribution gain*u*r (m/s).
    amplitude : float
        Wave-induced sway amplitude (m/s).
    period : float
        Wave period (s).
    bound : float
        Declared bound on |v_s| (m/s); must cover gain u_max r_max + amplitude.
        Set gain = amplitude = 0 for no sway.
    """

    gain: float = 0.1
    amplitude: float = 0.0
    period: float = 10.0
    bound: float = 0.02

    def __post_init__(self) -> None:
        object.__setattr__(self, "gain", nonnegative("sway.gain", self.gain))
        object.__setattr__(self, "amplitude", nonnegative("sway.amplitude", self.amplitude))
        object.__setattr__(self, "period", positive("sway.period", self.period))
        object.__setattr__(self, "bound", nonnegative("sway.bound", self.bound))


def nominal_kinematics(x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Nominal kinematics f(x) v of eq. (3); vectorised over leading axes.

    Parameters
    ----------
    x : array (..., 4)
        State [x, y, z, psi].
    v : array (..., 3)
        Input [u, w, r].

    Returns
    -------
    array (..., 4)
        [x_dot, y_dot, z_dot, psi_dot].
    """
    x = np.asarray(x, dtype=float)
    v = np.asarray(v, dtype=float)
    psi = x[..., 3]
    u, w, r = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([u * np.cos(psi), u * np.sin(psi), w, r + 0.0 * psi], axis=-1)


def kinematics(x: np.ndarray, v: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Perturbed kinematics f(x) v + [omega, 0] of eq. (11); vectorised.

    ``omega`` (..., 3) is the total inertial disturbance (current + sway term).
    """
    omega = np.asarray(omega, dtype=float)
    dx = nominal_kinematics(x, v)
    return dx + np.concatenate([omega, np.zeros(omega.shape[:-1] + (1,))], axis=-1)


def sinc(a: np.ndarray) -> np.ndarray:
    """S(a) = sin(a)/a with S(0) = 1 (unnormalised sinc), vectorised.

    sin(a)/a has no cancellation, so the quotient is accurate to round-off for every a != 0.
    """
    a = np.asarray(a, dtype=float)
    safe = np.where(a == 0.0, 1e-300, a)  # sin(1e-300)/1e-300 == 1.0
    return np.sin(safe) / safe


#: below this |a| = |r| dt / 2 the derivative of sin(a)/a uses its Taylor series (error < 1e-19)
SINC_SERIES_THRESHOLD = 0.1


def _dsinc_series(a: np.ndarray, a2: np.ndarray) -> np.ndarray:
    """d/da sin(a)/a by its Taylor series to a^9 (error < 1e-19 for |a| < 0.1)."""
    return a * (-1.0 / 3.0 + a2 * (1.0 / 30.0 + a2 * (-1.0 / 840.0 + a2 * (1.0 / 45360.0
                + a2 * (-1.0 / 3991680.0)))))


def dsinc(a: np.ndarray) -> np.ndarray:
    """S'(a) = (a cos a - sin a)/a^2 with S'(0) = 0, vectorised.

    The quotient cancels for small a, so |a| < :data:`SINC_SERIES_THRESHOLD` uses the
    Taylor series (error < 1e-19 there).
    """
    a = np.asarray(a, dtype=float)
    a2 = a * a
    series = _dsinc_series(a, a2)
    if a.size == 0 or a2.max() < SINC_SERIES_THRESHOLD ** 2:
        return series
    small = a2 < SINC_SERIES_THRESHOLD ** 2
    safe = np.where(small, 1.0, a)
    return np.where(small, series, (safe * np.cos(safe) - np.sin(safe)) / (safe * safe))


def unicycle_step(s: np.ndarray, v: np.ndarray, dt: float | np.ndarray) -> np.ndarray:
    """Exact solution of the nominal kinematics (eq. 3) after ``dt`` under a constant input; vectorised.

    x(dt) = x + dt u S(r dt / 2) [cos, sin](psi + r dt / 2), z + dt w, psi + dt r (S = :func:`sinc`):
    exact for every r, with no division by r.

    Parameters
    ----------
    s : array (..., 4)
        State [x, y, z, psi] (m, m, m, rad).
    v : array (..., 3)
        Input [u, w, r] (m/s, m/s, rad/s), held for ``dt``.
    dt : float or array (...)
        Elapsed time (s), broadcast against the leading axes.

    Returns
    -------
    array (..., 4)
    """
    s = np.asarray(s, dtype=float)
    v = np.asarray(v, dtype=float)
    dt = np.asarray(dt, dtype=float)
    u, w, r = v[..., 0], v[..., 1], v[..., 2]
    a = 0.5 * dt * r
    th = s[..., 3] + a
    k = dt * u * sinc(a)
    return np.stack(np.broadcast_arrays(s[..., 0] + k * np.cos(th), s[..., 1] + k * np.sin(th),
                                        s[..., 2] + dt * w, s[..., 3] + dt * r), axis=-1)
