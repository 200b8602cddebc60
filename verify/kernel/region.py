"""The verification region: the set every certified bound holds over.

A :class:`Region` is a box of error states e = [e_d, e_z, e_o] in one or both
heading hemispheres, together with the sets the exogenous quantities range over:

* bearing theta = atan2(e_y, e_x): any angle (the error e does not contain it);
* heading: psi - theta = phi with sin(phi) = e_o and cos(phi) = s sqrt(1 - e_o^2),
  s = -1 ("toward": the vehicle points at the target), +1 ("away"), or either ("both");
* desired velocity p_d_dot in P = {|xdot_d| <= pd_dot_max[0], |ydot_d| <= pd_dot_max[1],
  |zdot_d| <= pd_dot_max[2], sqrt(xdot_d^2 + ydot_d^2) <= pd_dot_xy_max};
* disturbance omega in Omega = {||omega||_2 <= omega_bar} (eq. Wset);
* nominal input v_hat in V = {|u| <= v_max[0], |w| <= v_max[1], |r| <= v_max[2]} (eq. 6).

Defaults come from a :class:`tubekit.scenario.Scenario`: e_d in [epsilon, e_d_max],
e_z in [-e_z_max, e_z_max], e_o in [-e_o_max, e_o_max], the scenario's heading,
the trajectory's velocity bounds, the disturbance's omega-bar and the input limits.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace
from typing import Any

from tubekit.exceptions import ConfigError
from tubekit.scenario import HEADINGS, HEMISPHERE_SIGN, Scenario
from tubekit.validation import interval, nonnegative, nonnegative_triple, positive_triple

__all__ = ["Region", "HEMISPHERE_SIGN"]



@dataclass(frozen=True)
class Region:
    """Error region R and exogenous sets (units: m, m/s, rad/s).

    Parameters
    ----------
    e_d : (lo, hi)
        Horizontal distance error range (m), 0 < lo < hi.
    e_z : (lo, hi)
        Vertical error range (m).
    e_o : (lo, hi)
        Orientation error range, -1 < lo < hi < 1 (|e_o| = 1 makes J singular).
    heading : str
        ``"toward"``, ``"away"`` or ``"both"`` (see module doc).
    pd_dot_max : (3,)
        Componentwise bound on |p_d_dot| (m/s).
    pd_dot_xy_max : float
        Bound on the horizontal target speed (m/s); at most hypot(pd_dot_max[:2]).
    omega_bar : float
        Disturbance bound (m/s), eq. (Wset).
    v_max : (3,)
        Input limits [u, w, r] (m/s, m/s, rad/s).
    """

    e_d: tuple[float, float]
    e_z: tuple[float, float]
    e_o: tuple[float, float]
    heading: str
    pd_dot_max: tuple[float, float, float]
    pd_dot_xy_max: float
    omega_bar: float
    v_max: tuple[float, float, float]

    def __post_init__(self) -> None:
        ed = interval("region.e_d", self.e_d)
        if ed[0] <= 0:
            raise ConfigError("region.e_d", "a lower end > 0 (e_o is undefined at e_d = 0)", list(ed))
        eo = interval("region.e_o", self.e_o)
        if eo[0] <= -1 or eo[1] >= 1:
            raise ConfigError("region.e_o", "an interval inside (-1, 1) (|e_o| = 1 makes J singular)", list(eo))
        object.__setattr__(self, "e_d", ed)
        object.__setattr__(self, "e_z", interval("region.e_z", self.e_z))
        object.__setattr__(self, "e_o", eo)
        if self.heading not in HEADINGS:
            raise ConfigError("region.heading", f"one of {HEADINGS}", self.heading)
        pd = nonnegative_triple("region.pd_dot_max", self.pd_dot_max)
        object.__setattr__(self, "pd_dot_max", pd)
        hxy = nonnegative("region.pd_dot_xy_max", self.pd_dot_xy_max)
        object.__setattr__(self, "pd_dot_xy_max", min(hxy, math.hypot(pd[0], pd[1])))
        object.__setattr__(self, "omega_bar", nonnegative("region.omega_bar", self.omega_bar))
        object.__setattr__(self, "v_max", positive_triple("region.v_max", self.v_max))

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_scenario(cls, scenario: Scenario, **overrides: Any) -> "Region":
        """The default region of ``scenario`` (module doc), with fields replaced by ``overrides``."""
        reg = scenario.region
        traj = scenario.trajectory
        fields = dict(
            e_d=(scenario.epsilon, reg.e_d_max),
            e_z=(-reg.e_z_max, reg.e_z_max),
            e_o=(-reg.e_o_max, reg.e_o_max),
            heading=reg.heading,
            pd_dot_max=tuple(float(x) for x in traj.velocity_bound()),
            pd_dot_xy_max=float(traj.horizontal_speed_bound()),
            omega_bar=float(scenario.disturbance.omega_bar),
            v_max=tuple(float(x) for x in scenario.limits.vector),
        )
        unknown = set(overrides) - set(fields)
        if unknown:
            raise ConfigError(f"region.{sorted(unknown)[0]}", f"one of {sorted(fields)}", sorted(unknown)[0])
        fields.update(overrides)
        return cls(**fields)

    def replace(self, **changes: Any) -> "Region":
        """A validated copy with fields replaced."""
        return replace(self, **changes)

    # ------------------------------------------------------------------ queries
    @property
    def hemisphere_signs(self) -> tuple[int, ...]:
        """Signs s of cos(psi - theta) covered: (-1,), (1,) or (-1, 1)."""
        if self.heading == "both":
            return (-1, 1)
        return (HEMISPHERE_SIGN[self.heading],)

    @property
    def epsilon(self) -> float:
        """Lower end of e_d (m): the paper's epsilon."""
        return self.e_d[0]

    def contains(self, e_d: float, e_z: float, e_o: float, cos_rel: float) -> bool:
        """True if the error (e_d, e_z, e_o) with cos(psi - theta) = ``cos_rel`` lies in R."""
        if not (self.e_d[0] <= e_d <= self.e_d[1] and self.e_z[0] <= e_z <= self.e_z[1]
                and self.e_o[0] <= e_o <= self.e_o[1]):
            return False
        return any(s * cos_rel > 0 for s in self.hemisphere_signs)

    def to_dict(self) -> dict:
        """JSON-friendly description (the ``region`` key of a certificate)."""
        d = asdict(self)
        for k, v in d.items():
            if isinstance(v, tuple):
                d[k] = list(v)
        d["bearing"] = "any angle in [0, 2 pi)"
        return d

    @classmethod
    def from_dict(cls, d: dict, where: str = "certificate.region") -> "Region":
        """Inverse of :meth:`to_dict` (``bearing`` is a description and is not read)."""
        from verify.kernel.parts import number, numbers, text
        try:
            return cls(e_d=numbers(d, "e_d", where, 2, none=None), e_z=numbers(d, "e_z", where, 2, none=None),
                       e_o=numbers(d, "e_o", where, 2, none=None), heading=text(d, "heading", where),
                       pd_dot_max=numbers(d, "pd_dot_max", where, 3, none=None),
                       pd_dot_xy_max=number(d, "pd_dot_xy_max", where), omega_bar=number(d, "omega_bar", where),
                       v_max=numbers(d, "v_max", where, 3, none=None))
        except ConfigError as exc:
            if exc.field.startswith("region."):
                raise ConfigError(f"{where}{exc.field[len('region'):]}", exc.expected, exc.received) from None
            raise

    def describe(self) -> str:
        """Multi-line printable description of the set."""
        hem = {"toward": "toward (cos(psi - theta) < 0: the vehicle points at the target)",
               "away": "away (cos(psi - theta) > 0)", "both": "both hemispheres"}[self.heading]
        pd = self.pd_dot_max
        v = self.v_max
        return "\n".join([
            f"  e_d in [{self.e_d[0]:.6g}, {self.e_d[1]:.6g}] m,  e_z in [{self.e_z[0]:.6g}, {self.e_z[1]:.6g}] m,"
            f"  e_o in [{self.e_o[0]:.6g}, {self.e_o[1]:.6g}]",
            f"  heading: {hem};  bearing theta = atan2(e_y, e_x): any",
            f"  |p_d_dot| <= [{pd[0]:.6g}, {pd[1]:.6g}, {pd[2]:.6g}] m/s,"
            f" horizontal speed <= {self.pd_dot_xy_max:.6g} m/s",
            f"  ||omega|| <= omega_bar = {self.omega_bar:.6g} m/s;  v_hat in V = |u| <= {v[0]:.6g}, |w| <= {v[1]:.6g},"
            f" |r| <= {v[2]:.6g}",
        ])
