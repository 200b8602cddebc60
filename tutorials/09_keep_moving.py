# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # 09 — A vehicle that must keep moving
#
# A torpedo-shaped AUV steers with fins, and fins give no force at rest: it must never command less than a
# minimum surge u_min. That changes three things the theorem leans on, and this tutorial walks through them:
#
# 1. the plans and the tube keep the surge above u_min (`limits.u_min`), and the backup cannot stop: it is a
#    **loiter**, a circle about an anchor at a constant surge;
# 2. the tracking theorem's terminal law follows the target's speed along the line of sight, which turns
#    negative when the target comes toward the vehicle. The terminal set gets a fourth face, a **cone behind
#    the target** (the *bearing* |φ| <= φ_f), where that speed keeps the law's surge above u_min;
# 3. where the theorem still says no, it names why: room beside the path for the loiter, or a target that
#    may stop.
#
# Last, a survey at 1 m/s with smooth (rate-limited) plans, where the cone and the terminal set's row faces hold
# together. The proof is `docs/verify.md`, steps 13e, 17b and 17c.

# %%
import os
import sys
from pathlib import Path

import matplotlib

if "ipykernel" not in sys.modules:  # a script draws off-screen; a notebook keeps its inline figures
    matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle, Wedge

import verify
from tubekit import check_promises, load_scenario, simulate
from tubekit.model.terminal_law import bearing
from tubekit.model.trajectory import Waypoints

QUICK = os.environ.get("TUBEKIT_QUICK") == "1"
FIGURES = (Path(os.environ["TUBEKIT_FIGURES"]) if "TUBEKIT_FIGURES" in os.environ
           else Path(__file__).resolve().parent / "figures")
FIGURES.mkdir(parents=True, exist_ok=True)
EXAMPLES = Path(verify.__file__).resolve().parent.parent / "examples"
DURATION = 20.0 if QUICK else 60.0

# %% [markdown]
# ## 1. The safe tier, and why tracking is refused
# `examples/keep_moving.toml`: a line target at 0.4 m/s, u_min = 0.2 m/s, the loiter backup, 0.1 m/s of current,
# and a rock 3 m off the path. The certificate gives the safe tier. Tracking fails one condition: the tracking
# theorem's candidate plan keeps the loiter's certified safe set (a circle of several metres) clear of every
# obstacle along the target's whole path, and 3 m is not enough room.

# %%
near = load_scenario(EXAMPLES / "keep_moving.toml")
cert_near = verify.certify(near)
print("tiers:", cert_near.tier_failures)
for c in cert_near.failures:
    print(f"  {c.condition}: {c.detail}")
print(f"loiter's safe radius: {cert_near.backup.safe_set.radius:.2f} m")

# %% [markdown]
# ## 2. The bearing face of the terminal set
# The bearing φ is the angle from the line of sight to the target's velocity: 0 when the vehicle trails the
# target, π when the target comes straight at it. The terminal law's surge is about
# (P cos φ + λ (d − d*)) / cos α, so inside a cone |φ| <= φ_f it stays above u_min as long as the target's
# speed P does not drop. Three states against a target at the origin moving along +x:

# %%
target, velocity = np.zeros(3), np.array([0.4, 0.0, 0.0])
for label, state in (("behind", [-1.5, 0.0, 0.0, 0.0]), ("beside", [0.0, -1.5, 0.0, np.pi / 2]),
                     ("ahead", [1.5, 0.0, 0.0, np.pi])):
    phi = bearing(np.array(state), target, velocity)
    print(f"{label:7s} bearing {phi:+.3f} rad, target speed along the line of sight {0.4 * np.cos(phi):+.3f} m/s")

# %% [markdown]
# ## 3. Both tiers, with room beside the path
# `examples/keep_moving_tracked.toml` is the same scenario with the rock 9 m off the path. The verifier finds a
# terminal set with a bearing face and proves, in interval arithmetic, that the cone is invariant under the
# terminal law and that the law's surge stays above u_min + κ̄_u:

# %%
far = load_scenario(EXAMPLES / "keep_moving_tracked.toml").with_changes(duration=DURATION)
cert = verify.certify(far)
law = cert.design.terminal
print("tiers:", cert.tier_failures)
print(f"X_f: d in [{law.d_lo:.3f}, {law.d_hi:.3f}] m, |alpha| <= {law.alpha_max:.3f} rad, "
      f"|bearing| <= {law.bearing_max:.3f} rad")
for c in cert.design.conditions:
    if "bearing" in c.condition or c.condition == "terminal_surge_floor":
        print(f"  [{'ok' if c.ok else 'FAIL'}] {c.condition}: {c.lhs:.6g} <= {c.rhs:.6g}")

# %% [markdown]
# ## 4. Fly it
# The run keeps every promise of both tiers: the applied surge never falls below u_min, and a plan is accepted
# at every period (`plan_available`: the candidate stands in wherever the solver's plan is rejected).

# %%
run = simulate(far, cert, progress=False)
promises = check_promises(run)
print("broken promises:", [p.name for p in promises if not p.ok])
print("plan_available:", next(p for p in promises if p.name == "plan_available").detail)
surge = run.inputs[:-1, 0]
print(f"smallest applied surge {np.nanmin(surge):.3f} m/s (u_min {far.limits.u_min} m/s); "
      f"tracking RMSE {run.metrics['tracking_rmse']:.3f} m")

# %%
fig, (top, side) = plt.subplots(1, 2, figsize=(12, 4.2), gridspec_kw={"width_ratios": [1.6, 1]})
top.plot(run.desired[:, 0], run.desired[:, 1], "k--", lw=1, label="target")
top.plot(run.states[:, 0], run.states[:, 1], "C0", lw=1.5, label="vehicle")
for o in far.obstacles:
    top.add_patch(Circle(o.center[:2], o.radius, color="0.4"))
step = max(1, len(run.t) // 5)
for i in range(0, len(run.t), step):  # the terminal set's sector behind the target, at a few instants
    p = run.desired[i, :2]
    toward = np.degrees(np.arctan2(-velocity[1], -velocity[0]))
    span = np.degrees(law.bearing_max)
    top.add_patch(Wedge(p, law.d_hi, toward - span, toward + span, width=law.d_hi - law.d_lo,
                        color="C2", alpha=0.25))
top.set_aspect("equal")
top.set_xlabel("x (m)")
top.set_ylabel("y (m)")
top.set_title("the run, with X_f's sector behind the target (green)")
top.legend(loc="upper left")
side.plot(run.t[:-1], surge, "C0", lw=1, label="applied surge u")
side.axhline(far.limits.u_min, color="C3", ls="--", label="u_min")
side.set_xlabel("t (s)")
side.set_ylabel("m/s")
side.set_title("the surge never falls below u_min")
side.legend()
fig.tight_layout()
fig.savefig(FIGURES / "09_keep_moving.png", dpi=100)
print("wrote", FIGURES / "09_keep_moving.png")

# %% [markdown]
# ## 5. A target that may stop
# Waypoints rest at their corners: the target's speed has no positive floor, no cone keeps the law's surge
# above u_min, and the verifier says so by name. The safe tier does not need it.

# %%
stopping = far.with_changes(trajectory=Waypoints(points=((0.0, 0.0, 0.0), (10.0, 0.0, 0.0), (20.0, 5.0, 0.0)),
                                                 speed=0.4), obstacles=())
cert_stop = verify.certify(stopping)
print("tiers:", cert_stop.tier_failures)
print(" ", cert_stop.failures[0].condition + ":", cert_stop.failures[0].detail)

# %% [markdown]
# ## 6. At survey speed, with smooth plans and no backup
# A vehicle whose velocity loop is part of the proof needs rate-limited plans (`limits.rate`), and the terminal
# set then carries a fifth kind of face: the plan's last row near the terminal law's own row (step 17c). The cone
# and these row faces hold together. `examples/keep_moving_survey.toml` is the survey a torpedo flies: a line at
# 1 m/s in 0.3 m/s of current, u_min 0.5 m/s, plans limited to (0.5 m/s², 0.5 m/s², 1 rad/s²), a rock 5 m off the
# path, and no backup law (the safe tier then rests on the tracking tier: a plan at every period).

# %%
survey = load_scenario(EXAMPLES / "keep_moving_survey.toml").with_changes(duration=DURATION)
cert_survey = verify.certify(survey)
law = cert_survey.design.terminal
print("tiers:", cert_survey.tier_failures)
print(f"X_f: d in [{law.d_lo:.2f}, {law.d_hi:.2f}] m, |bearing| <= {law.bearing_max:.3f} rad, "
      f"row faces (u, w, r) = ({law.row_u:.4f}, {law.row_w:.4f}, {law.row_r:.4f})")
run_survey = simulate(survey, cert_survey, progress=False)
kept = [p.name for p in check_promises(run_survey) if p.given and p.ok]
print("promises kept:", kept)
print(f"largest command jump per period: {run_survey.metrics['command_jump_max']}; "
      f"smallest clearance {run_survey.metrics['min_clearance']:.2f} m")
