"""A vehicle's thruster geometry, and the box of actuator limits (X_max, Z_max, N_max) it can produce.

The table ``[plant.vehicle.thrusters]`` (also inside a vehicle file) describes n thrusters by

* ``allocation``: the 3 × n matrix B: row 0 the surge force X (N) per newton of each thruster's
  thrust, row 1 the heave force Z (N/N), row 2 the yaw moment N (N m per N, i.e. m);
* ``thrust``: T, each thruster's largest thrust magnitude (N), symmetric: |f_i| <= T_i (give the
  weaker direction, e.g. a T200's reverse thrust);
* ``shares`` (optional, default [1, 1, 1]): the box's proportions, as fractions of each channel's
  solo capacity (only their ratios matter); a fourth share, the sway force Y's, with ``sway``;
* ``sway`` (optional): n numbers, the sway force (N/N) of each thruster; when given with three shares,
  every force the derivation uses is produced with zero sway force (the vehicle then has no lateral
  thrust, Y_max = 0); with a fourth share the box has a fourth channel, Y, and Y_max > 0 (the sway is
  then regulated by a loop of its own, ``tubekit.plant.dynamic``).

:class:`ThrusterGeometry` derives, by linear programs (``scipy.optimize.linprog``, HiGHS):

1. the solo capacity of channel c: C_c = max τ_c s.t. B f = τ_c e_c (sway f = 0), |f_i| <= T_i;
2. the box's half-widths (X_max, Z_max, N_max[, Y_max]) = t* (s_X C_X, s_Z C_Z, s_N C_N[, s_Y C_Y]), t* the
   largest t with every corner t·diag(s C)·(±1, ..., ±1) producible (one LP over t and a thrust vector per
   corner; the box is the convex hull of its corners, so all of it is then producible). A channel
   with share 0 gets the limit 0 (its corners ask 0 of it).
3. soundness: t* is shrunk by a relative :data:`SHRINK`, each corner's thrust vector by the same
   factor, and every corner is checked in floats: |B f − corner| <= :data:`RESIDUAL_TOLERANCE` ×
   scale (scale = max_c Σ_i |B_ci| T_i, N or N m) and |f_i| <= T_i exactly. This is a float LP
   certificate, not interval arithmetic: a corner is matched to within that residual.

A channel that cannot be produced at all (C_c = 0 with s_c > 0) is refused, naming
``plant.vehicle.thrusters.allocation``. Roll and pitch moments are not modelled (no such rows).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Mapping

import numpy as np

from tubekit.exceptions import ConfigError, SolverError
from tubekit.validation import is_number

__all__ = ["ThrusterGeometry", "FIELD", "KEYS", "CHANNELS", "LIMIT_KEYS", "SHRINK", "RESIDUAL_TOLERANCE",
           "MAX_THRUSTERS", "MAX_ENTRY", "MAX_THRUST", "MAX_SHARE"]

#: The table's full name in a scenario (every error names a field under it).
FIELD = "plant.vehicle.thrusters"
#: The keys of the table.
KEYS = ("allocation", "thrust", "shares", "sway")
#: The allocation's rows (and the sway row's): the channel each describes.
CHANNELS = ("surge X", "heave Z", "yaw N", "sway Y")
#: The vehicle parameters the derived box replaces (Y_max 0 without a fourth share: the box asks zero sway).
LIMIT_KEYS = ("X_max", "Z_max", "N_max", "Y_max")
#: Relative shrink of the LP's t* (and of its thrust vectors) before the float check.
SHRINK = 1e-6
#: Largest residual |B f − corner| accepted, relative to the scale max_c Σ_i |B_ci| T_i.
RESIDUAL_TOLERANCE = 1e-9
#: Most thrusters in one table.
MAX_THRUSTERS = 64
#: Largest |entry| of the allocation (N/N or m) and of ``sway`` (N/N).
MAX_ENTRY = 1e3
#: Largest thrust of one thruster (N).
MAX_THRUST = 1e7
#: Largest share (only the ratios of the shares matter).
MAX_SHARE = 1e6
#: Feasibility and optimality tolerances of HiGHS (tighter than its 1e-7 default: the float check is 1e-9).
_HIGHS = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}


def _number(field: str, value: Any, lo: float, hi: float, expected: str) -> float:
    """``value`` as a finite float in [lo, hi] (booleans, strings refused), else ConfigError naming ``field``."""
    try:
        x = float(value) if is_number(value) else math.nan
    except OverflowError:  # an int beyond the float range
        x = math.nan
    if not (math.isfinite(x) and lo <= x <= hi):
        raise ConfigError(field, expected, value)
    return x


def _sequence(field: str, value: Any, expected: str) -> list[Any]:
    """``value`` as a list (a list, tuple or 1-D array; never a string or a table), else ConfigError."""
    if isinstance(value, np.ndarray) and value.ndim == 1:
        return list(value)
    if not isinstance(value, (list, tuple)):
        raise ConfigError(field, expected, value)
    return list(value)


def _row(field: str, value: Any, n: int | None, lo: float, hi: float, what: str) -> tuple[float, ...]:
    """A list of ``n`` numbers (any n in 1..MAX_THRUSTERS when None), each in [lo, hi], as a tuple of floats."""
    count = f"{n} numbers (one per thruster: the allocation has {n} columns)" if n else \
        f"a list of 1 to {MAX_THRUSTERS} numbers"
    items = _sequence(field, value, f"{count}, each {what}")
    if (n is not None and len(items) != n) or not 1 <= len(items) <= MAX_THRUSTERS:
        raise ConfigError(field, f"{count}, each {what}", value)
    return tuple(_number(f"{field}[{i}]", x, lo, hi, what) for i, x in enumerate(items))


def _allocation(value: Any) -> tuple[tuple[float, ...], ...]:
    """The 3 × n allocation as 3 tuples of floats, else ConfigError naming the row or the entry."""
    field = f"{FIELD}.allocation"
    expected = ("a 3 x n matrix: 3 rows (surge X in N/N, heave Z in N/N, yaw N in m per thruster), each a list "
                f"of n numbers, 1 <= n <= {MAX_THRUSTERS}")
    rows = _sequence(field, value, expected)
    if len(rows) != 3:
        raise ConfigError(field, expected, value)
    entry = f"a finite number in [-{MAX_ENTRY:g}, {MAX_ENTRY:g}]"
    first = _row(f"{field}[0]", rows[0], None, -MAX_ENTRY, MAX_ENTRY, entry)
    return (first,) + tuple(_row(f"{field}[{c}]", rows[c], len(first), -MAX_ENTRY, MAX_ENTRY, entry)
                            for c in (1, 2))


def _shares(value: Any, with_sway: bool) -> tuple[float, ...]:
    """Three numbers >= 0 (four with a ``sway`` row: the fourth Y's), not all 0, else ConfigError naming ``shares``
    or ``shares[i]``."""
    field = f"{FIELD}.shares"
    items = _sequence(field, value, "3 numbers >= 0, not all 0")
    if len(items) not in ((3, 4) if with_sway else (3,)):
        raise ConfigError(field, "3 numbers >= 0 (surge, heave, yaw), not all 0" + (
            ", or 4 (and sway Y)" if with_sway else "; a fourth (sway Y) only with a sway row"), value)
    out = tuple(_number(f"{field}[{c}]", x, 0.0, MAX_SHARE, f"a finite number in [0, {MAX_SHARE:g}]")
                for c, x in enumerate(items))
    if not any(out):
        raise ConfigError(field, "3 numbers >= 0, not all 0 (the box's proportions)", value)
    return out  # type: ignore[return-value]


@dataclass(frozen=True)
class ThrusterGeometry:
    """n thrusters: their allocation, thrust limits, the box's shares (module doc).

    Parameters
    ----------
    allocation : 3 rows of n numbers
        B: surge force X (N/N), heave force Z (N/N), yaw moment N (m) per newton of each thruster.
    thrust : n numbers > 0
        T: each thruster's largest thrust magnitude (N), the same in both directions.
    shares : 3 (or 4) numbers >= 0, not all 0
        The box's proportions as fractions of each channel's solo capacity (default [1, 1, 1]); a fourth, the
        sway force's, only with ``sway``.
    sway : n numbers or None
        Sway force (N/N) of each thruster; given with three shares, every force used has zero sway; with four,
        the box has a lateral limit Y_max (:meth:`sway_limit`).

    The limits are derived (and checked) once, when the value is built; :meth:`limits` and
    :meth:`solo_capacity` return them. Equality and hashing use the four fields only.
    """

    allocation: tuple[tuple[float, ...], ...]
    thrust: tuple[float, ...]
    shares: tuple[float, ...] = (1.0, 1.0, 1.0)
    sway: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        allocation = _allocation(self.allocation)
        n = len(allocation[0])
        thrust = _row(f"{FIELD}.thrust", self.thrust, n, 0.0, MAX_THRUST,
                      f"a finite number of newtons in (0, {MAX_THRUST:g}]")
        for i, t in enumerate(thrust):
            if t <= 0.0:
                raise ConfigError(f"{FIELD}.thrust[{i}]", f"a finite number of newtons in (0, {MAX_THRUST:g}]", t)
        sway = None if self.sway is None else _row(f"{FIELD}.sway", self.sway, n, -MAX_ENTRY, MAX_ENTRY,
                                                   f"a finite number in [-{MAX_ENTRY:g}, {MAX_ENTRY:g}]")
        shares = _shares(self.shares, sway is not None)
        for name, value in (("allocation", allocation), ("thrust", thrust), ("shares", shares), ("sway", sway)):
            object.__setattr__(self, name, value)
        solo, limits = _derive(allocation, thrust, shares, sway)
        # cached (not dataclass fields: eq, hash and repr ignore them); replace() derives them again
        object.__setattr__(self, "_solo", solo)
        object.__setattr__(self, "_limits", limits)

    @property
    def count(self) -> int:
        """n, the number of thrusters."""
        return len(self.thrust)

    def limits(self) -> tuple[float, float, float]:
        """(X_max, Z_max, N_max) in N, N, N m: the box every point of which the thrusters produce."""
        return self._limits[:3]  # type: ignore[attr-defined, no-any-return]

    def sway_limit(self) -> float:
        """Y_max (N): the box's lateral half-width with a fourth share, else 0 (the box asks zero sway)."""
        return self._limits[3] if len(self._limits) > 3 else 0.0  # type: ignore[attr-defined, no-any-return]

    def vehicle_limits(self) -> dict[str, float]:
        """{X_max, Z_max, N_max, Y_max}: the vehicle parameters the box replaces (:data:`LIMIT_KEYS`)."""
        return dict(zip(LIMIT_KEYS, (*self.limits(), self.sway_limit())))

    def solo_capacity(self) -> tuple[float, ...]:
        """(C_X, C_Z, C_N[, C_Y]) in N, N, N m[, N]: the largest |X|, |Z|, |N| (and |Y| with a fourth share) each
        produced with the others 0."""
        return self._solo  # type: ignore[attr-defined, no-any-return]

    @classmethod
    def from_dict(cls, d: Any) -> ThrusterGeometry:
        """Parse the ``[plant.vehicle.thrusters]`` table (ConfigError naming the field)."""
        if not isinstance(d, Mapping):
            raise ConfigError(FIELD, "a table with keys allocation, thrust and optional shares, sway", d)
        for key in d:
            if key not in KEYS:
                raise ConfigError(f"{FIELD}.{key}", f"one of the keys {list(KEYS)}", key)
        for key in ("allocation", "thrust"):
            if key not in d:
                raise ConfigError(f"{FIELD}.{key}", "present (allocation and thrust are required)", "missing")
        return cls(**{k: d[k] for k in KEYS if k in d})

    def to_dict(self) -> dict[str, Any]:
        """The table (lists: TOML and JSON round-trip); ``sway`` only when given."""
        out: dict[str, Any] = {"allocation": [list(r) for r in self.allocation], "thrust": list(self.thrust),
                               "shares": list(self.shares)}
        if self.sway is not None:
            out["sway"] = list(self.sway)
        return out


# ---- the derivation --------------------------------------------------------------------------------------------
def _equalities(allocation: tuple[tuple[float, ...], ...], thrust: tuple[float, ...],
                sway: tuple[float, ...] | None) -> tuple[np.ndarray, np.ndarray, float]:
    """(B, A, scale): B (3 or 4 × n, with the sway row) in N or N m per N; A = B diag(T) / scale, the LP's rows
    over g = f / T in [-1, 1]; scale = max_c Σ_i |B_ci| T_i (N or N m)."""
    b = np.array(allocation + ((sway,) if sway is not None else ()), dtype=float)
    t = np.array(thrust, dtype=float)
    scale = float(np.max(np.abs(b[:3]) @ t))
    return b, b * t / (scale if scale > 0.0 else 1.0), scale


def _linprog(cost: np.ndarray, a_eq: np.ndarray, bounds: list[tuple[float | None, float | None]],
             what: str) -> np.ndarray:
    """The minimiser of cost·x s.t. a_eq x = 0 within ``bounds`` (HiGHS), else SolverError naming ``what``."""
    from scipy.optimize import linprog  # scipy.optimize only when a thruster table is given

    res = linprog(cost, A_eq=a_eq, b_eq=np.zeros(a_eq.shape[0]), bounds=bounds, method="highs", options=_HIGHS)
    if res.status != 0 or res.x is None:
        raise SolverError(f"{FIELD}: the linear program of the {what} failed ({res.message}); the thruster table "
                          "passed validation, so this is a solver failure, not an input error")
    return np.asarray(res.x, dtype=float)


def _solo(a: np.ndarray, channel: int) -> float:
    """max τ with A g = τ e_channel / scale-units, |g| <= 1 (A scaled as in :func:`_equalities`)."""
    n = a.shape[1]
    target = np.zeros((a.shape[0], 1))
    target[channel, 0] = 1.0
    cost = np.zeros(n + 1)
    cost[-1] = -1.0
    x = _linprog(cost, np.hstack([a, -target]), [(-1.0, 1.0)] * n + [(0.0, None)],
                 f"{CHANNELS[channel]} channel's solo capacity")
    return float(x[-1])


def _corners(dims: int = 3) -> np.ndarray:
    """The 2^dims sign vectors (±1, ..., ±1), shape (2^dims, dims)."""
    return np.array(list(itertools.product((1.0, -1.0), repeat=dims)))


def _box(a: np.ndarray, widths: np.ndarray) -> tuple[float, np.ndarray]:
    """(t*, g (K, n)): max t such that A g^k = t·(σ_k ∘ widths, 0) for every corner k of the len(widths)-box,
    |g^k| <= 1."""
    rows, n = a.shape
    dims = len(widths)
    signs = _corners(dims)
    count = len(signs)
    a_eq = np.zeros((count * rows, 1 + count * n))
    for k, sigma in enumerate(signs):
        a_eq[k * rows:k * rows + dims, 0] = -sigma * widths
        a_eq[k * rows:(k + 1) * rows, 1 + k * n:1 + (k + 1) * n] = a
    cost = np.zeros(1 + count * n)
    cost[0] = -1.0
    x = _linprog(cost, a_eq, [(0.0, None)] + [(-1.0, 1.0)] * (count * n), "box of limits")
    return float(x[0]), x[1:].reshape(count, n)


def _check_corners(b: np.ndarray, thrust: np.ndarray, limits: np.ndarray, forces: np.ndarray, scale: float) -> None:
    """Every corner σ ∘ limits (the rows beyond the limits' at 0) is B f for its f (within the residual tolerance),
    |f_i| <= T_i exactly."""
    for sigma, f in zip(_corners(len(limits)), forces):
        target = np.concatenate([sigma * limits, np.zeros(b.shape[0] - len(limits))])
        residual = float(np.max(np.abs(b @ f - target)))
        if residual > RESIDUAL_TOLERANCE * scale or np.any(np.abs(f) > thrust):
            raise SolverError(f"{FIELD}: the corner {tuple(float(x) for x in sigma * limits)} of the derived box "
                              f"failed its float check (residual {residual:.3g}, largest |f_i| / T_i "
                              f"{float(np.max(np.abs(f) / thrust)):.9g}); the limits are not certified")


@lru_cache(maxsize=256)
def _derive(allocation: tuple[tuple[float, ...], ...], thrust: tuple[float, ...], shares: tuple[float, ...],
            sway: tuple[float, ...] | None) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """((C_X, C_Z, C_N[, C_Y]), (X_max, Z_max, N_max[, Y_max])) of validated inputs (module doc, steps 1-3)."""
    b, a, scale = _equalities(allocation, thrust, sway)
    dims = len(shares)
    solo = np.array([_solo(a, c) * scale for c in range(dims)])
    share = np.array(shares) / max(shares)
    for c in range(dims):
        if share[c] > 0.0 and not solo[c] > RESIDUAL_TOLERANCE * scale:
            raise ConfigError(f"{FIELD}.allocation", f"thrusters able to produce the {CHANNELS[c]} channel alone (its "
                              f"share is {shares[c]:g} > 0, but no thrust vector within the limits gives it without "
                              "the other channels" + (" and sway" if sway is not None else "") + ": no authority)",
                              [list(r) for r in allocation])
    widths = share * solo
    t_star, g = _box(a, widths / scale)
    factor = 1.0 - SHRINK
    limits = factor * t_star * widths
    forces = factor * g * np.array(thrust)
    _check_corners(b, np.array(thrust), limits, forces, scale)
    # + 0.0: a channel of share 0 (or an LP's -0.0) reads 0.0
    return tuple(float(x) + 0.0 for x in solo), tuple(float(x) + 0.0 for x in limits)
