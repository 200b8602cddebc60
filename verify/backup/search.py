"""The backup's design: a deterministic grid search whose every candidate is proved by :func:`certify_backup`.

:func:`design_backup` searches surge fractions u_b of ū (above ω̄_xy), safe-set levels c and shapes β; the float
rate of :func:`verify.backup.proof.rate_sampled` filters, :func:`verify.backup.certify_backup` proves. A candidate
whose sampled held rate is positive (:func:`verify.backup.proof.held_rate_sampled`: values every interval bound of
the proof's bisection encloses) is refuted without the bisection, and proved only if :meth:`_Search.fallback`
returns it: the same designs, without spending a whole bisection budget on each refuted candidate. Without
``fits`` it returns the certified design with the smallest safe radius.

**Gentle designs** (``smooth=True``, issue 22). On the dynamic plant the backup's command is followed by a
velocity loop whose error grows with the command's rate (:func:`verify.backup.backup_tick_change`), and the
smallest safe set is the fastest command. The caller then passes ``fits(law, safe) -> float``, the ratio of
the loop error that the candidate's command rate causes to the error the disturbance bound assumed
(:func:`verify.vehicle.compose.solve_dynamic`): the search returns the smallest certified design with
``fits < 1``, scanning the levels on the coarser :data:`GENTLE_LEVEL_STEP` grid up to
:data:`GENTLE_MAX_LEVEL`; ``fits`` is evaluated before the (costly) proof, so only a design that fits is proved.
Every smoothing length (fades, ramp, heave band) shrinks as β grows, so the command is gentlest at the smallest
β of the grid: a level where even that does not fit is *hopeless* and skipped before its shape is searched. The
levels grow gentler as they grow (longer fades and ramp), so the hopeless levels of a law are taken to be a
prefix of the grid and the first level that is not is found by bisection (:meth:`_Search.first_fitting`: about
six evaluations of ``fits`` per law instead of one per level). Past that level the scan evaluates ``fits`` only
where some shape has a negative rate (:meth:`_Search._defer`): elsewhere the level is skipped whatever the ratio,
and by the same prefix property it is not hopeless, so :meth:`_Search.fallback` has no use for it. The prefix is
a property of the search, not of the proof: measured on the shipped dynamic scenario that reaches the search
(70 series of levels, not one ratio rising with the level; ``tests/test_verify_vehicle_compose.py``), and where
it failed the search would only return a larger safe set, proved like any other. When none fits it returns the
candidate with the smallest ratio, proved (certified or not), so the caller can say by how much.

The smooth designs' yaw bands are :data:`SMOOTH_BAND_FRACTIONS` of the unstable angle χ_u (the widest band
χ_u/2 is the gentlest yaw command: the command's rate grows like k (k + E_r)/χ_0), then :data:`NARROW_YAW_BAND`.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from flint import arb

from tubekit.model.backup import SafeSet, StationKeeping
from tubekit.validation import nonnegative, positive
from verify.backup.continuous import cone_angle, continuous_best_shape
from verify.backup.proof import (BACKUP_MAX_BOXES, certify_backup, held_rate_sampled, ramp_window, rates_sampled,
                                 tick_distance)
from verify.backup.protocol import BackupCertificate, Fits
from verify.kernel.intervals import lower, upper

__all__ = ["design_backup", "UNSTABLE_FRACTION", "SMOOTH_BAND_FRACTIONS", "NARROW_YAW_BAND", "SMOOTH_SEARCH_BOXES",
           "GENTLE_LEVEL_STEP", "GENTLE_MAX_LEVEL", "REFUTE_MARGIN", "Fits"]

#: The smooth design's unstable axis angle χ_u as a fraction of the cone angle χ_c = acos √(ω̄_xy/u_b).
UNSTABLE_FRACTION = 0.8
#: Yaw bands χ_0 of the smooth design as fractions of χ_u, widest first (χ_u/2: ρ just reaches 1 between its zeros).
SMOOTH_BAND_FRACTIONS = (0.5, 0.25)
#: The narrow yaw band χ_0 (rad): the kinematic design's, and the smooth design's last resort.
NARROW_YAW_BAND = 0.05
#: Bisection budget of each candidate of the smooth design (a refuted candidate costs its whole budget).
SMOOTH_SEARCH_BOXES = 1024
#: Level step (m) and largest level (m) of a gentle search (``fits`` given).
GENTLE_LEVEL_STEP = 0.25
GENTLE_MAX_LEVEL = 12.0

#: A sampled held rate above this (m/s) refutes a candidate before its proof (:meth:`_Search._refuted`): far above
#: the floats' rounding of rates of order 1 m/s, so the proof, in Arb, would refute it too.
REFUTE_MARGIN = 1e-9

#: The smallest shape β (m) of the grid: the gentlest command at a level (the longest fades and ramp).
MIN_SHAPE = 0.05


def depth_band(handover: tuple[float, float], limits: tuple[float, float, float], omega_z: float,
               tick: float) -> tuple[float, float]:
    """(z_0, Z) (m) of a saturated heave w = −w̄ sat((z − z*)/z_0): z_0 half the hand-over's depth error (at least
    1 mm), Z the larger of that error and z_0 + h (w̄ + ω̄_z) (``backup_depth_hold``), with a relative 1e-9 of room."""
    band = max(1e-3, 0.5 * handover[1])
    return band, max(handover[1], band + tick * (limits[1] + omega_z)) * (1 + 1e-9)


def _candidates(limits: tuple[float, float, float], omega_xy: float) -> list[tuple[float, float]]:
    """(u_b, k) pairs to try: surge fractions of u_max above ω̄_xy, the full yaw rate."""
    return [(f * limits[0], limits[2]) for f in (0.5, 0.625, 0.75, 0.875, 1.0) if f * limits[0] > omega_xy]


def design_backup(*, omega_xy: float, omega_z: float, limits: tuple[float, float, float], tick: float,
                  handover: tuple[float, float] = (0.0, 0.0), max_boxes: int = BACKUP_MAX_BOXES,
                  yaw_rate_error: float = 0.0, smooth: bool = False, min_level: float = 0.2,
                  fits: Fits | None = None) -> BackupCertificate:
    """The certified station-keeping design with the smallest safe radius >= ``min_level`` (m) on a fixed grid
    (deterministic; module doc), or with ``fits`` the smallest whose command the velocity loop can follow.

    ``smooth=True`` (issue 22) designs the rate-bounded law: for each candidate (c, β) the fades are
    d_0 = d_1 = d_tick (the largest ``backup_fade`` admits: the gentlest fade), the depth band is
    Z = max(Z_0, h_z + T_xy (w_b + ω̄_z)) with T_xy = (c − β − h_xy)/(u_b + ω̄_xy) (so the heave
    channel never shortens the ramp; T_xy and Z with max(u_b, ū), max(w_b, w̄): the ramp blends the hand-over's
    command into the law), the heave band z_0 = Z − h (w_b + ω̄_z) (the widest
    ``backup_depth_hold`` admits), the ramp t_r = :func:`verify.backup.ramp_window` (the longest ``backup_ramp``
    admits); the yaw law is the continuous one (no jump abeam) with χ_u = :data:`UNSTABLE_FRACTION` · χ_c for
    each u_b, and its bands are tried widest first (module doc); each candidate gets at most
    :data:`SMOOTH_SEARCH_BOXES` intervals. Returns the last refuted candidate when none is certified.
    """
    wxy, wz, h = nonnegative("omega_xy", omega_xy), nonnegative("omega_z", omega_z), positive("tick", tick)
    e_r = nonnegative("yaw_rate_error", yaw_rate_error)
    lim = tuple(float(x) for x in limits)
    search = _Search(wxy, wz, lim, h, handover, min(max_boxes, SMOOTH_SEARCH_BOXES) if smooth else max_boxes, e_r,
                     smooth, positive("min_level", min_level), fits if smooth else None)
    for band in ((*SMOOTH_BAND_FRACTIONS, None) if smooth else (None,)):
        found = search.run(band)
        if found is not None:
            return found
    return search.fallback()


@dataclasses.dataclass
class _Search:
    """The grid search's settings and what it has seen (the closest candidate, the last refuted one)."""

    wxy: float
    wz: float
    limits: tuple[float, float, float]
    h: float
    handover: tuple[float, float]
    boxes: int
    e_r: float
    smooth: bool
    min_level: float
    fits: Fits | None
    last: BackupCertificate | None = None
    #: The last candidate refuted by :meth:`_refuted` (not proved) when it came after :attr:`last`, else None.
    last_refuted: tuple[StationKeeping, SafeSet] | None = None
    closest: tuple[float, StationKeeping, SafeSet] | None = None
    #: Each (law, level) asked, in asking order: its ratio at β = MIN_SHAPE, or None for a level the scan passed
    #: without bounding it (:meth:`_defer`: no shape has a negative rate there; :meth:`fallback` passes it over).
    ratios: dict[tuple[StationKeeping, float], float | None] = dataclasses.field(default_factory=dict)

    def _levels(self) -> np.ndarray:
        if self.fits is not None:
            start = max(GENTLE_LEVEL_STEP, self.min_level)
            return np.round(np.arange(start, max(GENTLE_MAX_LEVEL, start) + 1e-4, GENTLE_LEVEL_STEP), 6)
        return np.round(np.arange(max(0.2, self.min_level), max(6.0, self.min_level) + 1e-4, 0.05), 6)

    def _depth(self) -> tuple[float, float]:
        """(z_0, Z) (m): the heave band and the depth half-height before smoothing (:func:`depth_band`)."""
        return depth_band(self.handover, self.limits, self.wz, self.h)

    def _law(self, surge: float, yaw: float, band: float | None) -> StationKeeping:
        z0, _ = self._depth()
        kw = _yaw_law(surge, self.wxy, self.smooth)
        width = NARROW_YAW_BAND if band is None else band * kw["unstable"]
        return StationKeeping(surge=surge, yaw_rate=yaw, yaw_band=width, heave=self.limits[1], heave_band=z0, **kw)

    def _certify(self, law: StationKeeping, safe: SafeSet) -> BackupCertificate:
        return certify_backup(law, safe, omega_xy=self.wxy, omega_z=self.wz, limits=self.limits, tick=self.h,
                              handover=self.handover, max_boxes=self.boxes, yaw_rate_error=self.e_r)

    def _fits(self, law: StationKeeping, safe: SafeSet) -> bool:
        """True when no ``fits`` is given or the candidate fits; else remember the closest candidate."""
        if self.fits is None:
            return True
        ratio = float(self.fits(law, safe))
        if ratio < 1.0:
            return True
        if self.closest is None or ratio < self.closest[0]:
            self.closest = (ratio, law, safe)
        return False

    def _hopeless(self, law: StationKeeping, level: float) -> bool:
        """True when even the smallest shape β (the longest fades and ramp: the gentlest command, module doc)
        does not fit at ``level``; then no β does, and the level is only remembered for :meth:`fallback`."""
        if self.fits is None:
            return False
        ratio = self.ratios.get((law, level))
        if ratio is None:  # not asked yet, or deferred
            trial, safe = self._candidate(law, level, MIN_SHAPE)
            ratio = self.ratios[(law, level)] = float(self.fits(trial, safe))
        return ratio >= 1.0

    def _defer(self, law: StationKeeping, level: float) -> None:
        """Record that the scan reached ``level`` where no shape has a negative rate: the level is skipped whether
        or not it is hopeless, so it is not bounded. It lies past the law's first fitting level, so under the
        prefix property (module doc) it is not hopeless, and :meth:`fallback` passes it over."""
        if self.fits is not None:
            self.ratios.setdefault((law, level), None)

    def first_fitting(self, law: StationKeeping, levels: np.ndarray) -> int | None:
        """Index of the first of ``levels`` (ascending, m) that is not hopeless for ``law``, by bisection on the
        hopeless prefix (module doc); None when the last level is hopeless too (then no level fits)."""
        if self.fits is None:
            return 0 if len(levels) else None
        if len(levels) == 0 or self._hopeless(law, float(levels[-1])):
            return None
        lo, hi = 0, len(levels) - 1  # levels[hi] is not hopeless
        while lo < hi:
            mid = (lo + hi) // 2
            if self._hopeless(law, float(levels[mid])):
                lo = mid + 1
            else:
                hi = mid
        return lo

    def _candidate(self, law: StationKeeping, level: float, shape: float) -> tuple[StationKeeping, SafeSet]:
        safe = SafeSet(level=float(level), shape=shape, depth=self._depth()[1])
        if not self.smooth:
            return law, safe
        return _smoothed(law, safe, self.wxy, self.wz, self.h, self.handover, self.limits)

    def run(self, band: float | None) -> BackupCertificate | None:
        """The smallest certified (and fitting) design with yaw band ``band`` (a fraction of χ_u; None: narrow)."""
        best: BackupCertificate | None = None
        grid = self._levels()
        for surge, yaw in _candidates(self.limits, self.wxy):
            law = self._law(surge, yaw, band)
            levels = grid if best is None else grid[grid < best.safe_set.level]
            start = self.first_fitting(law, levels)
            if start is None:
                continue
            for level in levels[start:]:
                shape = _best_shape(law, float(level), self.wxy, self.handover[0], self.e_r)
                if shape is None:  # skipped whatever its ratio: not bounded (fallback passes it over)
                    self._defer(law, float(level))
                    continue
                if self._hopeless(law, float(level)):
                    continue
                trial, safe = self._candidate(law, float(level), shape)
                if not self._fits(trial, safe) or self._refuted(trial, safe):
                    continue
                self.last, self.last_refuted = self._certify(trial, safe), None
                if self.last.certified:
                    best = self.last
                    break
        return best

    def _refuted(self, law: StationKeeping, safe: SafeSet) -> bool:
        """True when a sampled held rate is positive (:func:`verify.backup.proof.held_rate_sampled`, by more than
        :data:`REFUTE_MARGIN`): the proof would refute ``backup_level_set`` after spending its whole bisection
        budget. The candidate is then the last refuted one; :meth:`fallback` proves it if it is returned."""
        if not held_rate_sampled(law, safe, self.wxy, self.h, yaw_err=self.e_r) > REFUTE_MARGIN:
            return False
        self.last, self.last_refuted = None, (law, safe)
        return True

    def fallback(self) -> BackupCertificate:
        """Nothing certified (and fitting): the closest candidate proved (each law's hopeless level with the smallest
        ratio at β = :data:`MIN_SHAPE` gets its shape now), else the last refuted one, else the full-speed law at
        level 6 m."""
        family: dict[StationKeeping, tuple[float, float]] = {}
        for (law, level), ratio in self.ratios.items():  # each law's gentlest hopeless level (in asking order)
            if ratio is None or ratio < 1.0:  # deferred: past the law's first fitting level, so not hopeless
                continue
            if law not in family or ratio < family[law][0]:
                family[law] = (ratio, level)
        gentlest = None  # the first family's gentlest shape: its ratio is known (a best shape may break the loop)
        for law, (ratio, level) in sorted(family.items(), key=lambda t: t[1][0]):
            if self.closest is not None and ratio >= self.closest[0]:
                break
            if gentlest is None and math.isfinite(ratio):
                gentlest = (ratio, *self._candidate(law, level, MIN_SHAPE))
            shape = _best_shape(law, level, self.wxy, self.handover[0], self.e_r)
            if shape is not None:
                self._fits(*self._candidate(law, level, shape))
        if gentlest is not None and (self.closest is None or not math.isfinite(self.closest[0])):
            self.closest = gentlest  # every best shape broke the loop: the fixed point needs a finite E to go on
        if self.closest is not None:
            return self._certify(self.closest[1], self.closest[2])
        if self.last_refuted is not None:
            return self._certify(*self.last_refuted)
        if self.last is not None:
            return self.last
        _, depth = self._depth()
        return self._certify(self._law(self.limits[0], self.limits[2], None), SafeSet(level=6.0, shape=1.0,
                                                                                        depth=depth))


def _yaw_law(surge: float, wxy: float, smooth: bool) -> dict:
    """The yaw law's keywords: the continuous law with χ_u = UNSTABLE_FRACTION · χ_c when ``smooth`` (without a
    cone, ω̄_xy >= u_b, χ_u = UNSTABLE_FRACTION · π/2: the refuted fallback then names ``backup_unstable``)."""
    if not smooth:
        return {}
    cone = cone_angle(surge, wxy)
    return {"yaw_law": "continuous", "unstable": UNSTABLE_FRACTION * (cone if cone > 0.0 else math.pi / 2)}


def _smoothed(law: StationKeeping, safe: SafeSet, wxy: float, wz: float, h: float,
              handover: tuple[float, float], limits: tuple[float, float, float]) -> tuple[StationKeeping, SafeSet]:
    """The smooth design's fades, depth band, heave band and ramp for (c, β) (see :func:`design_backup`)."""
    d_tick = tick_distance(law, safe, wxy, h)
    if not d_tick > 0.0:
        return law, safe
    surge, heave = max(law.surge, limits[0]), max(law.heave, limits[1])  # the ramp's speeds (blend from V)
    t_xy = (arb(safe.level) - arb(safe.shape) - arb(handover[0])) / (arb(surge) + arb(wxy))
    depth = max(safe.depth, upper(arb(handover[1]) + t_xy * (arb(heave) + arb(wz))))
    safe = SafeSet(level=safe.level, shape=safe.shape, depth=depth)
    band = max(law.heave_band, lower(arb(depth) - arb(h) * (arb(law.heave) + arb(wz))) * (1 - 1e-9))
    ramp = ramp_window(law, safe, omega_xy=wxy, omega_z=wz, tick=h, handover=handover, limits=limits)
    law = dataclasses.replace(law, surge_fade=d_tick, yaw_fade=d_tick, heave_band=band, ramp=max(0.0, ramp))
    return law, safe


def _best_shape(law: StationKeeping, level: float, omega_xy: float, handover: float,
                yaw_err: float = 0.0) -> float | None:
    """The shape β on a grid with the most negative sampled level-set rate at ``level``, or None (the continuous
    law's shapes evaluated at once and pruned, :func:`verify.backup.continuous.continuous_best_shape`)."""
    shapes = np.round(np.arange(MIN_SHAPE, level - handover, MIN_SHAPE), 6)
    if shapes.size == 0:
        return None
    if law.yaw_law == "continuous":
        i, rate = continuous_best_shape(law, level, shapes, omega_xy, yaw_err=yaw_err)
        return float(shapes[i]) if rate < 0.0 else None
    rates = rates_sampled(law, level, shapes, omega_xy, yaw_err=yaw_err)
    rates = np.where(np.isnan(rates), np.inf, rates)
    i = int(np.argmin(rates))   # the first of the most negative
    return float(shapes[i]) if rates[i] < 0.0 else None
