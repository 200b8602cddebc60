"""Regenerate every committed artefact the code produces, and the sidecar that pins it to the code.

    python docs/regenerate.py                      # all: the README's figures, the notebooks, the sidecar
    python docs/regenerate.py --skip-notebooks     # figures and sidecar only (about a minute)
    python docs/regenerate.py --campaign DIR       # also redraw docs/campaign_ecdf.png from a finished campaign
    python docs/regenerate.py --check              # recompute the fingerprint, compare with the sidecar (exit 1)

What is written: ``docs/reproduce_{top_view,errors,inputs,rho}.png`` (from ``tubekit reproduce``),
``docs/envelope.png`` (``tubekit envelope verify/scenarios/paper_currents.toml --plot``), the executed
notebooks ``tutorials/notebooks/*.ipynb`` (``tutorials/build_notebooks.py``, full sizes), the measured
table of ``docs/reproduce.md`` (between its ``regenerate.py`` markers) and ``docs/artefacts.json``.

The sidecar ``docs/artefacts.json`` holds the *fingerprint*: the numbers these artefacts show that can be
recomputed in seconds (each shipped scenario's certificate: verdict, tiers, σ, tube; the paper
reproduction's kinematic tube and baseline runs: clearance, e_d, RMSE, replaced plans, backup time), a
hash of the drawing code, and the SHA-256 of every file written. ``tests/test_regenerate.py`` recomputes
the fingerprint and compares; ``tests/test_tutorials.py`` checks that each notebook's cells are its
tutorial's and that it carries the same fingerprint. A change of code that moves any of these numbers
therefore fails the tests until this script is run again. Numbers only a long run shows (the campaign,
the dynamic plant, timings) are not recomputed: they are pinned by hash, not re-derived.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from tubekit.jsonable import write_text

ROOT = Path(__file__).resolve().parents[1]
SIDECAR = ROOT / "docs" / "artefacts.json"
REPRODUCE_MD = ROOT / "docs" / "reproduce.md"
#: ``tubekit reproduce`` output file -> committed copy.
REPRODUCE_FIGURES = {"fig2_top_view.png": "docs/reproduce_top_view.png", "fig3_errors.png": "docs/reproduce_errors.png",
                     "fig4_inputs.png": "docs/reproduce_inputs.png", "rho.png": "docs/reproduce_rho.png"}
ENVELOPE_FIGURE = "docs/envelope.png"
CAMPAIGN_FIGURE = "docs/campaign_ecdf.png"
#: The drawing code whose change makes every committed figure stale.
DRAWING_CODE = ("tubekit/app/plots.py", "tubekit/app/plots_envelope.py", "tubekit/app/plots_campaign.py",
                *sorted(p.relative_to(ROOT).as_posix() for p in (ROOT / "tubekit" / "plotting").glob("*.py")))
#: (name, scenario file relative to ROOT or "paper" for tubekit.paper_scenario(), law or None for the file's own).
CERTIFICATES = (("paper", "paper", None), ("paper_currents", "verify/scenarios/paper_currents.toml", None),
                ("paper_currents/paper-law", "verify/scenarios/paper_currents.toml", "paper"),
                ("certifiable", "verify/scenarios/certifiable.toml", None), ("paper_law", "examples/paper_law.toml", None))
#: Metrics of the reproduction's runs kept in the fingerprint (tube run; baseline under ``baseline``).
RUN_KEYS = ("min_clearance", "min_e_d", "tracking_rmse", "max_input_ratio", "saturated_steps", "replaced_steps",
            "backup_s", "encirclements")
BEGIN, END = "<!-- regenerate.py: measured begin -->", "<!-- regenerate.py: measured end -->"
#: Relative tolerance of the comparison (closed-loop numbers depend on solver round-off across machines).
REL_TOL = 1e-5


def _round(x):
    """``x`` with floats at 7 significant digits (lists and dicts element-wise); NaN/inf as strings."""
    if isinstance(x, bool) or x is None or isinstance(x, (int, str)):
        return x
    if isinstance(x, dict):
        return {k: _round(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_round(v) for v in x]
    x = float(x)
    return float(f"{x:.7g}") if math.isfinite(x) else str(x)


def sha256(path: Path) -> str:
    """SHA-256 (hex) of a file's bytes."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def drawing_hash() -> str:
    """One SHA-256 over the drawing modules' sources (:data:`DRAWING_CODE`)."""
    h = hashlib.sha256()
    for rel in DRAWING_CODE:
        h.update((ROOT / rel).read_bytes())
    return h.hexdigest()


def _scenario(source: str):
    import tubekit
    return tubekit.paper_scenario() if source == "paper" else tubekit.load_scenario(ROOT / source)


def certificate_fingerprint() -> dict:
    """Per entry of :data:`CERTIFICATES`: certified, tiers, σ (1/s) and the one-period tube (e_d m, e_z m, e_o)."""
    import verify
    out = {}
    for name, source, law in CERTIFICATES:
        scenario = _scenario(source)
        cert = verify.certify(scenario, law=law or scenario.controller.law)
        out[name] = _round({"certified": bool(cert.certified), "tiers": cert.tiers.to_dict(),
                            "sigma": cert.sigma.value, "tube": [float(r) for r in cert.tube.rho]})
    return out


def reproduce_fingerprint() -> dict:
    """The paper reproduction's kinematic runs, as ``tubekit reproduce`` computes them (same pipeline)."""
    import tubekit
    from tubekit.app.certified import certify_design
    from tubekit.app.study import run_tube_and_baseline

    scenario = tubekit.paper_scenario()
    tube, base = run_tube_and_baseline(scenario, certify_design(scenario).tightening, progress=False)
    t, b = tube.to_dict(), base.to_dict()
    return _round({**{k: t.get(k) for k in RUN_KEYS}, "baseline": {k: b.get(k) for k in RUN_KEYS}})


def fingerprint() -> dict:
    """Everything the tests recompute: certificates, the reproduction's runs, the drawing code's hash."""
    return {"certificates": certificate_fingerprint(), "reproduce": reproduce_fingerprint(),
            "drawing_code": drawing_hash()}


def differences(found, stored, where: str = "") -> list[str]:
    """Human-readable differences between two fingerprints (floats within :data:`REL_TOL`)."""
    if isinstance(found, dict) and isinstance(stored, dict):
        out = [f"{where}.{k}: missing on one side" for k in sorted(set(found) ^ set(stored))]
        for k in sorted(set(found) & set(stored)):
            out += differences(found[k], stored[k], f"{where}.{k}" if where else k)
        return out
    if isinstance(found, list) and isinstance(stored, list) and len(found) == len(stored):
        return [d for i, (a, b) in enumerate(zip(found, stored)) for d in differences(a, b, f"{where}[{i}]")]
    numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (found, stored))
    if numbers and math.isclose(found, stored, rel_tol=REL_TOL, abs_tol=1e-9):
        return []
    return [] if found == stored else [f"{where}: now {found!r}, stored {stored!r}"]


def measured_table(fp: dict) -> str:
    """The markdown table of ``docs/reproduce.md`` between the markers, from a fingerprint."""
    r = fp["reproduce"]
    rows = [("min_clearance (m, vehicle ball to obstacle surface; < 0 overlaps)", "min_clearance"),
            ("min_e_d (m; epsilon = 0.1)", "min_e_d"), ("tracking_rmse (m)", "tracking_rmse"),
            ("max_input_ratio (max abs(v_i) / v_i bound)", "max_input_ratio"), ("saturated_steps", "saturated_steps"),
            ("replaced plans", "replaced_steps"), ("backup law active (s)", "backup_s"),
            ("encirclements (the target makes 2)", "encirclements")]
    lines = [BEGIN, "| metric (kinematic plant, 100 s) | tube | baseline (no tube) |", "|---|---|---|"]
    for label, key in rows:
        lines.append(f"| {label} | {_cell(r.get(key))} | {_cell(r['baseline'].get(key))} |")
    lines.append(f"\nGenerated by `python docs/regenerate.py` (pinned by `docs/artefacts.json`).\n{END}")
    return "\n".join(lines)


def _cell(v) -> str:
    return "—" if v is None else (f"{v:.4g}" if isinstance(v, float) else str(v))


def write_measured_table(fp: dict) -> None:
    """Replace the block between the markers of ``docs/reproduce.md`` (appended when absent)."""
    text = REPRODUCE_MD.read_text()
    block = measured_table(fp)
    if BEGIN in text and END in text:
        text = text[:text.index(BEGIN)] + block + text[text.index(END) + len(END):]
    else:
        text = text.rstrip() + "\n\n## Measured (generated)\n\n" + block + "\n"
    write_text(REPRODUCE_MD, text)


def _tubekit(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "tubekit", *args], check=True, cwd=ROOT)


def regenerate_figures() -> tuple[list[str], dict]:
    """``tubekit reproduce`` and ``tubekit envelope`` into a temporary directory; copy the README's figures."""
    written = []
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "reproduce"
        _tubekit("reproduce", "--out", str(out), "--no-progress", "-q")
        for name, rel in REPRODUCE_FIGURES.items():
            shutil.copyfile(out / name, ROOT / rel)
            written.append(rel)
        fp_check = json.loads((out / "metrics.json").read_text())
        _tubekit("envelope", "verify/scenarios/paper_currents.toml", "--plot", str(ROOT / ENVELOPE_FIGURE), "-q")
        written.append(ENVELOPE_FIGURE)
    found = _round({k: fp_check.get(k) for k in RUN_KEYS})
    return written, found


def regenerate_campaign(campaign_dir: Path) -> dict:
    """Redraw ``docs/campaign_ecdf.png`` from ``DIR/runs.parquet``; return the campaign's headline numbers."""
    import pyarrow.parquet as pq
    from tubekit.app.plots_campaign import ecdf_figure

    rows = pq.read_table(campaign_dir / "runs.parquet").to_pylist()
    spec = json.loads((campaign_dir / "campaign.json").read_text())["spec"]
    epsilon = float(spec.get("base", {}).get("epsilon", 0.5))
    ecdf_figure(rows, epsilon).savefig(ROOT / CAMPAIGN_FIGURE, dpi=100)
    summary = json.loads((campaign_dir / "summary.json").read_text())
    return {"runs": summary.get("runs"), "runs_by_tier": summary.get("runs_by_tier"),
            "largest_max_rho_ratio": (summary.get("largest_max_rho_ratio") or {}).get("max_rho_ratio")}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare only; exit 1 on a difference")
    parser.add_argument("--skip-notebooks", action="store_true", help="do not rebuild the notebooks")
    parser.add_argument("--campaign", type=Path, help="a finished campaign directory (redraws campaign_ecdf.png)")
    args = parser.parse_args(argv)
    stored = json.loads(SIDECAR.read_text()) if SIDECAR.is_file() else {}
    fp = fingerprint()
    if args.check:
        diff = differences(fp, stored.get("fingerprint", {}))
        print("\n".join(diff) or "artefacts match the code")
        return 1 if diff else 0
    if args.campaign is not None and not (args.campaign / "runs.parquet").is_file():
        parser.error(f"--campaign: {args.campaign}/runs.parquet does not exist")
    written, from_cli = regenerate_figures()
    if differences(from_cli, {k: fp["reproduce"].get(k) for k in RUN_KEYS}):
        print("tubekit reproduce and the fingerprint's fast path disagree:", from_cli, file=sys.stderr)
        return 1
    campaign = regenerate_campaign(args.campaign) if args.campaign else stored.get("campaign")
    if args.campaign:
        written.append(CAMPAIGN_FIGURE)
    if not args.skip_notebooks:
        sys.path.insert(0, str(ROOT / "tutorials"))
        import build_notebooks
        written += build_notebooks.build_all(stamp={"fingerprint": fp})
    write_measured_table(fp)
    files = dict(stored.get("files", {}))
    files.update({rel: sha256(ROOT / rel) for rel in written})
    write_text(SIDECAR, json.dumps({"command": "python docs/regenerate.py", "fingerprint": fp, "campaign": campaign,
                                    "files": dict(sorted(files.items()))}, indent=1) + "\n")
    print(f"wrote {len(written)} artefacts and {SIDECAR.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    os.chdir(ROOT)
    sys.exit(main())
