"""What safety costs the mission: time without a plan, tracking error and laps, with and without the candidate.

Usage::

    python benchmarks/mission.py [--duration S] [--json FILE] [--only NAME ...] [--fhocp-mode realtime|converged]
                                 [--spread K]

For each scenario (the paper's Section VI; each shipped scenario certified on both tiers —
``verify/scenarios/paper_currents.toml``, ``verify/scenarios/certifiable.toml``, ``examples/paper_law.toml`` — with its
variants with a faster current (period 3 s) and a steady one; the two-rock transit) the certificate is computed
(:func:`verify.certify`), then the tube run is simulated under the scenario's own current three ways: as shipped
(the shifted candidate, :mod:`tubekit.loop.candidate`, and recovery plans, ``Tightening.recovers``), without
recovery plans (``controller.recovery = false``) and with neither (``controller.candidate = false`` too: the
replay, then the backup), beside the baseline (the nominal MPC alone). Printed per run: the tiers, the seconds the backup law
ran (no plan followed), the periods the candidate was accepted, the tracking RMSE (m), its ratio to the
baseline's, the laps about the circle's centre where there is one, and the promises broken. Everything is
measured on the run; nothing here is timed.

``--spread K`` runs the shipped loop from K starts 2 cm from the scenario's instead (:func:`spread`), to tell a
figure of the design from a figure of one run.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import verify
from tubekit import paper_scenario, simulate
from tubekit.loop.pipeline import CertifiedRun, certified_run
from tubekit.model.trajectory import Line
from tubekit.scenario import Obstacle, Scenario, load_scenario

ROOT = Path(__file__).resolve().parents[1]


def transit() -> Scenario:
    """The transit of issue 31: a line at 0.24 m/s, a 0.12 m/s cross current, two rocks 0.9 m off the path."""
    base = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")
    return base.with_changes(
        name="transit", trajectory=Line(start=(-12.0, 0.0, 0.0), direction_velocity=(0.24, 0.0, 0.0)),
        initial_state=(-12.8, 0.0, 0.2, 0.0), obstacles=(Obstacle((-4.0, 0.9, 0.0), 0.4), Obstacle((4.0, -0.9, 0.0), 0.4)),
        epsilon=0.5, workspace=((-20.0, -10.0, -5.0), (30.0, 10.0, 5.0)),
        **{"disturbance.amplitude": (0.0, 0.0, 0.0), "disturbance.constant": (0.0, 0.12, 0.0)})


def variants(name: str, scenario: Scenario) -> dict[str, Scenario]:
    """``scenario`` as shipped, with a faster current (period 3 s) and with a steady one (the amplitude held)."""
    steady = scenario.with_changes(**{"disturbance.amplitude": (0.0, 0.0, 0.0),
                                      "disturbance.constant": tuple(scenario.disturbance.amplitude)})
    return {name: scenario, f"{name}_fast": scenario.with_changes(**{"disturbance.period": 3.0}),
            f"{name}_steady": steady}


def scenarios() -> dict[str, Scenario]:
    """The scenarios of the module doc, by name: Section VI, every shipped scenario certified on both tiers with its
    variants (:func:`variants`), the transit."""
    shipped = {"paper_currents": verify.SCENARIOS_DIR / "paper_currents.toml",
               "certifiable": verify.SCENARIOS_DIR / "certifiable.toml",
               "paper_law": ROOT / "examples" / "paper_law.toml"}
    out: dict[str, Scenario] = {"section_vi": paper_scenario()}
    for name, path in shipped.items():
        out.update(variants(name, load_scenario(path)))
    out["transit"] = transit()
    return out


def recovery_seconds(done: CertifiedRun) -> float:
    """Seconds (rounded to 1 ms) a recovery plan was followed in the run (tracking not in force)."""
    return round(float(done.run.recovery[:-1].sum()) * float(done.run.t[1] - done.run.t[0]), 3)


def measure(name: str, scenario: Scenario, duration: float, mode: str = "realtime") -> dict:
    """The certificate's tiers and, for the tube run with and without the candidate and the baseline, the figures
    (``mode``: the FHOCP's ``controller.fhocp_mode``, not a certificate input)."""
    scenario = scenario.with_changes(duration=duration, **{"controller.fhocp_mode": mode})
    cert = verify.certify(scenario)
    tight = cert.best_effort_tightening()
    base = simulate(scenario, None, progress=False)
    out = {"scenario": name, "tiers": cert.tiers.to_dict(), "baseline_rmse": base.metrics["tracking_rmse"]}
    for label, candidate, recovery in (("shipped", True, True), ("no_recovery", True, False),
                                       ("replay_only", False, False)):
        sc = scenario.with_changes(**{"controller.candidate": candidate, "controller.recovery": recovery})
        done = certified_run(sc, tight, progress=False)
        m = done.metrics
        out[label] = {"backup_s": m["backup_s"], "recovery_s": recovery_seconds(done),
                      "candidate_periods": int(done.run.candidate.sum()),
                      "tracking_rmse": m["tracking_rmse"],
                      "rmse_ratio": m["tracking_rmse"] / out["baseline_rmse"] if out["baseline_rmse"] else math.nan,
                      "encirclements": m.get("encirclements"), "broken": list(done.broken),
                      "premises_failed": [p.name for p in done.promises if p.tier == "premise" and not p.ok]}
    return out


def spread(name: str, scenario: Scenario, duration: float, starts: int, offset: float = 0.02,
           mode: str = "realtime") -> dict:
    """The shipped loop from ``starts`` starts ``offset`` m from the scenario's (evenly on a horizontal circle), each
    certified on its own start (the start is part of the design): how the figures spread when nothing but the
    start moves by a fraction of the vehicle's size. Per run: backup and recovery seconds, the RMSE ratio to the
    baseline from the same start, laps; summarised as min / median / max and the runs followed by a plan throughout."""
    runs = []
    for i in range(starts):
        angle = 2.0 * math.pi * i / starts
        x0 = list(scenario.initial_state)
        x0[0] += offset * math.cos(angle)
        x0[1] += offset * math.sin(angle)
        sc = scenario.with_changes(duration=duration, initial_state=tuple(x0), **{"controller.fhocp_mode": mode})
        cert = verify.certify(sc)
        base = simulate(sc, None, progress=False).metrics["tracking_rmse"]
        done = certified_run(sc, cert.best_effort_tightening(), progress=False)
        m = done.metrics
        runs.append({"tiers": cert.tiers.to_dict(), "backup_s": m["backup_s"],
                     "recovery_s": recovery_seconds(done),
                     "rmse_ratio": m["tracking_rmse"] / base, "encirclements": m.get("encirclements"),
                     "broken": list(done.broken)})

    def stats(key: str) -> list[float] | None:
        values = sorted(r[key] for r in runs if r[key] is not None)
        return [values[0], values[len(values) // 2], values[-1]] if values else None
    return {"scenario": name, "starts": starts, "offset_m": offset,
            "tiers": sorted({json.dumps(r["tiers"], sort_keys=True) for r in runs}),
            "plan_throughout": sum(r["backup_s"] == 0 and r["recovery_s"] == 0 for r in runs),
            "broken": sum(bool(r["broken"]) for r in runs),
            **{k: stats(k) for k in ("backup_s", "recovery_s", "rmse_ratio", "encirclements")}}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=100.0, help="simulated seconds per run (default 100)")
    parser.add_argument("--only", nargs="*", help="scenario names to run (default all)")
    parser.add_argument("--json", type=Path, help="also write the rows as JSON")
    parser.add_argument("--fhocp-mode", choices=("realtime", "converged"), default="realtime",
                        help="the FHOCP's mode (default realtime, as shipped)")
    parser.add_argument("--spread", type=int, metavar="K",
                        help="instead: the shipped loop from K starts 2 cm from the scenario's (min / median / max)")
    args = parser.parse_args(argv)
    rows = []
    for name, sc in scenarios().items():
        if args.only and name not in args.only:
            continue
        row = (spread(name, sc, args.duration, args.spread, mode=args.fhocp_mode) if args.spread
               else measure(name, sc, args.duration, args.fhocp_mode))
        rows.append(row)
        print(json.dumps(row), flush=True)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
