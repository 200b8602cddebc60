"""The backup-law proof protocol: what the theorem asks of the proof of one backup-law kind, and the registry.

A backup law (:class:`tubekit.model.backup.BackupLaw`: ``kind``, ``command``, ``bounds``, ``within``, ``blends``,
``to_dict``) is evaluated in ``tubekit.model``; its proof lives here, one :class:`BackupProof` per ``kind``:

* :meth:`BackupProof.design` — a law of this kind and its safe set for the certificate's bounds (step 13 of
  ``docs/verify.md``; what :func:`verify.theorem.tiers.backup_of` asks for);
* :meth:`BackupProof.certify` — the proof (or the refutation, each failed inequality named) that a given law
  keeps a given safe set invariant, with the hand-over it was proved for (steps 12–13;
  :func:`verify.theorem.tiers.recertify_backup`, and ``tubekit recheck`` on the stored law);
* :meth:`BackupProof.command_rate` and :meth:`BackupProof.tick_change` — the bounds on the command's rate and
  on its change from one tick to the next along the plant (step 13a), which the velocity loop is charged on the
  dynamic plant (:mod:`verify.vehicle.compose`);
* :meth:`BackupProof.sway_change` — the same for the sway command of a law that commands sway (0 otherwise);
* :meth:`BackupProof.summary_lines` — the law's lines of a certificate's text.

The safe set's footprint for the terminal condition (step 11) is the :class:`tubekit.model.backup.SafeSet`
every proof returns (horizontal radius ``level`` and depth band ``depth``; ``shape`` is the law's own and may be
0), read by :meth:`tubekit.model.backup.BackupPlan.footprint`.

:func:`proof_for` finds the proof of a law (or of a kind) in :data:`BACKUP_PROOFS`; :func:`register_backup_proof`
adds one. Importing :mod:`verify.backup` registers the built-in proofs (station keeping,
:mod:`verify.backup.station_keeping`). **A second backup law** is one module beside ``tubekit/model/backup.py``
(registered with :func:`tubekit.model.backup.register_backup_law`) and one module beside
:mod:`verify.backup.station_keeping` whose proof object is registered here; the certificate's JSON carries the
law's ``kind`` and :class:`BackupCertificate` reads it back through :func:`tubekit.model.backup.backup_law_from_dict`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import asdict, dataclass
from typing import Any, Callable, Protocol, runtime_checkable

from tubekit.exceptions import ConfigError
from tubekit.model.backup import BACKUP_LAWS, BackupLaw, SafeSet, StationKeeping, backup_law_from_dict
from verify.kernel.parts import block, bound, integer, item, number, numbers
from verify.theorem.design import Condition

__all__ = ["BackupCertificate", "BackupProof", "Fits", "BACKUP_PROOFS", "DEFAULT_BACKUP_KIND", "register_backup_proof",
           "proof_for"]

#: ``fits(law, safe)``: the ratio (dimensionless) of the loop error a candidate's command causes to the error
#: assumed (:func:`verify.vehicle.compose.solve_dynamic`); a design search keeps the candidates with ratio < 1.
Fits = Callable[[BackupLaw, SafeSet], float]

#: The kind :func:`verify.theorem.tiers.backup_of` designs: a scenario has no backup field (``docs/verify.md`` §7).
DEFAULT_BACKUP_KIND = StationKeeping.kind


@dataclass(frozen=True)
class BackupCertificate:
    """A backup law, its safe set, the disturbance it holds against and every checked condition.

    Attributes
    ----------
    law : BackupLaw
        The law (its ``kind`` names its proof, :func:`proof_for`).
    safe_set : SafeSet
        The invariant set about the anchor; its footprint is the terminal condition's.
    omega_xy, omega_z : float
        ω̄_xy, ω̄_z (m/s) the proof holds against.
    tick : float
        h (s), the law's hold.
    rate_bound, rate_sampled : float
        The proved upper bound of the level set's rate (m/s, ``inf`` when none) and a sampled value of it.
    boxes : int
        Intervals the proof examined (a work unit).
    conditions : tuple of Condition
        Every inequality of the proof, with both numbers.
    handover : (float, float)
        Horizontal distance and depth error (m) from the anchor the hand-over was proved for (the last arc's
        margins, plus ``anchor_reach`` horizontally).
    yaw_rate_error : float
        E_r (rad/s) the proof holds against (0 on the kinematic plant).
    anchor_reach : float
        Largest horizontal distance (m) from the plan's nominal end at which the loop may place the anchor
        (``docs/verify.md`` step 12); included in ``handover[0]``.
    """

    law: BackupLaw
    safe_set: SafeSet
    omega_xy: float
    omega_z: float
    tick: float
    rate_bound: float
    rate_sampled: float
    boxes: int
    conditions: tuple[Condition, ...]
    handover: tuple[float, float] = (0.0, 0.0)
    yaw_rate_error: float = 0.0
    anchor_reach: float = 0.0

    @property
    def certified(self) -> bool:
        """True when every condition holds."""
        return all(c.ok for c in self.conditions)

    @property
    def failures(self) -> tuple[Condition, ...]:
        """The conditions that do not hold."""
        return tuple(c for c in self.conditions if not c.ok)

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-able data (floats, strings, booleans); the law as :meth:`BackupLaw.to_dict` (with ``kind``)."""
        out: dict[str, Any] = {
            "law": self.law.to_dict(), "safe_set": asdict(self.safe_set), "omega_xy": self.omega_xy,
            "omega_z": self.omega_z, "tick": self.tick, "rate_bound": self.rate_bound,
            "rate_sampled": self.rate_sampled, "boxes": self.boxes, "certified": self.certified,
            "handover": list(self.handover), "conditions": [c.to_dict() for c in self.conditions]}
        if self.yaw_rate_error:  # issue 22's keys appear only when on: older certificates keep their JSON
            out["yaw_rate_error"] = self.yaw_rate_error
        if self.anchor_reach:  # written only when the anchor may move: certificates without it keep their JSON
            out["anchor_reach"] = self.anchor_reach
        return out

    @classmethod
    def from_dict(cls, d: dict[str, Any], where: str = "certificate.backup") -> "BackupCertificate":
        """Inverse of :meth:`to_dict` (``certified`` is recomputed; a law without ``kind`` is station keeping, as
        every certificate before issue 30 stored it; ConfigError naming the key)."""
        law_ = _law(block(d, "law", where), f"{where}.law")
        safe_ = _safe_set(block(d, "safe_set", where), f"{where}.safe_set")
        conds = item(d, "conditions", where)
        if not isinstance(conds, list):
            raise ConfigError(f"{where}.conditions", "a list of conditions", type(conds).__name__)
        return cls(law=law_, safe_set=safe_, omega_xy=number(d, "omega_xy", where),
                   omega_z=number(d, "omega_z", where), tick=number(d, "tick", where),
                   rate_bound=bound(d, "rate_bound", where), rate_sampled=number(d, "rate_sampled", where),
                   boxes=integer(d, "boxes", where),
                   conditions=tuple(Condition.from_dict(c, f"{where}.conditions[{i}]") for i, c in enumerate(conds)),
                   handover=numbers(d, "handover", where, 2),
                   yaw_rate_error=number(d, "yaw_rate_error", where) if "yaw_rate_error" in d else 0.0,
                   anchor_reach=_reach(d, where))

    def summary_lines(self) -> list[str]:
        """Human-readable lines for a certificate's text (the law's own lines from its proof)."""
        return proof_for(self.law).summary_lines(self)


def _reach(d: dict[str, Any], where: str) -> float:
    """The stored anchor reach (m; 0 when absent, as certificates before it stored none); ConfigError below 0."""
    reach = number(d, "anchor_reach", where) if "anchor_reach" in d else 0.0
    if reach < 0.0:
        raise ConfigError(f"{where}.anchor_reach", "a distance >= 0 (m)", reach)
    return reach


def _law(raw: dict[str, Any], where: str) -> BackupLaw:
    """:func:`tubekit.model.backup.backup_law_from_dict`, a missing parameter of a dataclass law named by its key."""
    cls = BACKUP_LAWS.get(raw.get("kind", DEFAULT_BACKUP_KIND))
    if cls is not None and dataclasses.is_dataclass(cls):
        for f in dataclasses.fields(cls):
            required = f.init and f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
            if required and f.name not in raw:
                raise ConfigError(f"{where}.{f.name}", "present", "missing")
    return backup_law_from_dict(raw, where)


def _safe_set(raw: dict[str, Any], where: str) -> SafeSet:
    """The stored safe set, a ConfigError naming ``where.key`` when a value is refused."""
    try:
        return SafeSet(**{k: number(raw, k, where) for k in ("level", "shape", "depth")})
    except ConfigError as exc:
        if exc.field.startswith(where):
            raise
        raise ConfigError(f"{where}.{exc.field.split('.')[-1]}", exc.expected, exc.received) from None


@runtime_checkable
class BackupProof(Protocol):
    """The proof of one backup-law kind (module doc). Every bound is a float rounded in the safe direction."""

    @property
    def kind(self) -> str:
        """The :attr:`tubekit.model.backup.BackupLaw.kind` this proof covers."""
        ...

    def design(self, *, omega_xy: float, omega_z: float, limits: tuple[float, float, float], tick: float,
               handover: tuple[float, float], yaw_rate_error: float = 0.0, smooth: bool = False,
               fits: Fits | None = None, surge_floor: float | None = None) -> BackupCertificate:
        """A law of this kind and its safe set, proved for ω̄_xy, ω̄_z (m/s), V = ``limits`` (m/s, m/s, rad/s),
        the tick h (s), the hand-over (m, m) and E_r (rad/s); ``smooth``: the command's rate must be bounded
        (the dynamic plant); ``fits``: keep only candidates whose command the velocity loop can follow;
        ``surge_floor``: the plans' minimum surge u_min (m/s), below which a law that keeps moving must not go (a law
        that stops ignores it and fails ``backup_min_surge``). A design that does not certify is returned with its
        failed conditions."""
        ...

    def certify(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                limits: tuple[float, float, float], tick: float, handover: tuple[float, float] = (0.0, 0.0),
                yaw_rate_error: float = 0.0) -> BackupCertificate:
        """Prove (or refute, naming each failed inequality) that ``safe`` is invariant under ``law`` held at the
        tick h (s) against ω̄_xy, ω̄_z (m/s) and E_r (rad/s), from every hand-over within ``handover`` (m, m)."""
        ...

    def command_rate(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                     limits: tuple[float, float, float],
                     loop_error: tuple[float, float, float]) -> tuple[float, float, float]:
        """Upper bounds on |u̇| (m/s²), |ẇ| (m/s²), |ṙ| (rad/s²) of the law's command along the plant (``inf``
        where none holds), with the velocity loop's error E = ``loop_error`` (m/s, m/s, rad/s)."""
        ...

    def tick_change(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                    limits: tuple[float, float, float], loop_error: tuple[float, float, float],
                    tick: float) -> tuple[float, float, float]:
        """Bounds (m/s, m/s, rad/s) on the change of the held command from one tick h (s) to the next during
        the backup, the hand-over included: the per-tick jumps the velocity loop's bound is charged."""
        ...

    def sway_change(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                    limits: tuple[float, float, float], loop_error: tuple[float, float, float],
                    tick: float) -> float:
        """Bound (m/s) on the change of the held sway command from one tick to the next during the backup (0 for a
        law that never commands sway): the sway loop's per-tick jump."""
        ...

    def summary_lines(self, cert: BackupCertificate) -> list[str]:
        """The certificate's text lines for a backup of this kind."""
        ...


#: Backup proofs by the ``kind`` of the law they prove; :func:`register_backup_proof` adds one.
BACKUP_PROOFS: dict[str, BackupProof] = {}


def register_backup_proof(proof: BackupProof) -> BackupProof:
    """Register ``proof`` under its ``kind`` and return it; ConfigError when it does not satisfy
    :class:`BackupProof`, its kind is not a registered backup law (:data:`tubekit.model.backup.BACKUP_LAWS`), or
    another proof holds the kind."""
    if not isinstance(proof, BackupProof):
        raise ConfigError("backup.proof", "an object with kind, design, certify, command_rate, tick_change, "
                          "sway_change and summary_lines", type(proof).__name__)
    kind = proof.kind
    if not isinstance(kind, str) or kind not in BACKUP_LAWS:
        raise ConfigError("backup.kind", f"the kind of a registered backup law ({sorted(BACKUP_LAWS)})", kind)
    if BACKUP_PROOFS.get(kind, proof) is not proof:
        raise ConfigError("backup.kind", f"a kind without a proof (proved: {sorted(BACKUP_PROOFS)})", kind)
    BACKUP_PROOFS[kind] = proof
    return proof


def proof_for(law_or_kind: BackupLaw | str) -> BackupProof:
    """The registered proof of a backup law (by its ``kind``) or of a kind; ConfigError ``backup.kind`` when none."""
    kind = law_or_kind if isinstance(law_or_kind, str) else getattr(law_or_kind, "kind", None)
    proof = BACKUP_PROOFS.get(kind) if isinstance(kind, str) else None
    if proof is None:
        raise ConfigError("backup.kind", f"a backup-law kind with a proof (proved: {sorted(BACKUP_PROOFS)})", kind)
    return proof
