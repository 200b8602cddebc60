# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # 04 — Tightened sets: V̄, the per-arc margins and the exact arc check
#
# The FHOCP plans for the *nominal* vehicle. Tutorial 03 bounded how far the real vehicle
# drifts from the nominal within one period (the one-period tube). This tutorial turns that
# tube into the constraints the planner must respect, in four steps:
#
# 1. **V̄ = V − κ̄** — the input box left for the nominal once the ancillary feedback has
#    taken its share, so the real input never saturates (docs/verify.md, section 3, step 7);
# 2. **per-arc margins** M_j — how much each arc j of a plan must stay inside R and away from
#    obstacles; they grow along the horizon because the *previous* plan may have to be replayed
#    from the new measured state (step 8);
# 3. **the exact arc check** `tubekit.loop.plan_check.check_plan` — a plan is accepted only if the
#    constraints hold along the whole continuous arcs, not only at the FHOCP's nodes (step 9);
# 4. **the hand-off** `Certificate.tightening` — the `Tightening` the FHOCP and the loop use.

# %%
import dataclasses
import os
from dataclasses import replace
import sys
from pathlib import Path

import matplotlib

if "ipykernel" not in sys.modules:  # a script draws off-screen; a notebook keeps its inline figures
    matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle

import verify
from tubekit import error_coordinates, load_scenario
from tubekit.loop.plan_check import check_plan, plan_arcs
from tubekit.tightening import MARGIN_COLUMNS, Tightening
from verify.theorem.sampled import horizon_margins

QUICK = os.environ.get("TUBEKIT_QUICK") == "1"
FIGURES = (Path(os.environ["TUBEKIT_FIGURES"]) if "TUBEKIT_FIGURES" in os.environ
           else Path(__file__).resolve().parent / "figures")
FIGURES.mkdir(parents=True, exist_ok=True)

# %% [markdown]
# ## The certificate we tighten with
# The paper's vehicle against the paper's current (`paper_currents.toml`, tutorial 03), certified
# with the corrected law; we fix σ = 3.125 1/s (`controller.sigma`) so that the feedback's share
# of the tightening (κ̄, the heading it turns) is visible.

# %%
scenario = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")
scenario = scenario.with_changes(controller=replace(scenario.controller, sigma=3.125))
cert = verify.certify(scenario)
problem = cert.design.problem
print(f"certified: {cert.certified}, sigma = {cert.sigma.value:g} 1/s, "
      f"one-period tube rho = {np.round(cert.tube.rho, 4)} (e_d m, e_z m, e_o)")

# %% [markdown]
# ## Step 1: V̄ = V − κ̄
# Within a period the feedback asks for at most |κ_j| ≤ κ̄_j (tutorial 03). If the nominal
# plans with |v̂_j| ≤ V_j − κ̄_j, then v = v̂ + κ stays in V: the clip of the loop is never
# active, so the input the theorem analyses is the input that is applied. Two *necessary*
# conditions come with it: the nominal must still out-run the target plus the current
# (`keep_up[u]`) and turn the line of sight as fast as a cross current at e_d = ε can
# (`yaw_budget`).

# %%
V = np.array(cert.limits)
need = np.array([problem.pd_xy + problem.omega_xy, problem.pd_z + problem.omega_z, problem.omega_xy / problem.eps])
for j, (ax, unit, why) in enumerate((("u", "m/s", "target speed + omega_xy"), ("w", "m/s", "|zdot_d| + omega_z"),
                                     ("r", "rad/s", "omega_xy / eps"))):
    print(f"  {ax}: V = {V[j]:g} {unit}, kappa_bar = {cert.kappa_bar[j]:.4f}  ->  V_bar = {cert.v_bar[j]:.4f} {unit}"
          f"   (needs >= {need[j]:.4f} = {why})")

# %% [markdown]
# ## Step 2: the per-arc margins, and why they grow
# Each FHOCP sample, the nominal is reset to the measured state. If the new plan is rejected
# (step 3), the loop **replays the previous accepted plan**, shifted by one period, from the new
# state. That state is off the old plan's prediction by at most the Cartesian tube of one period
# (‖Δp_xy‖ ≤ p_xy, |Δz| ≤ p_z, |Δψ| ≤ ψ̄). Under the same inputs the heading offset stays and the
# position offset drifts by ū ψ̄ τ. So if arc j of a plan meets margin M_j, the replay's arc j − 1
# meets M_j − Δ(jδ) — which must be the margin of arc j − 1:
#
#     M_0 = the one-period tube,   M_j = M_{j−1} + Δ(jδ).
#
# `verify.theorem.sampled.horizon_margins` computes them; `cert.margins` stores them.

# %%
tube = cert.design.tube
margins = horizon_margins(problem, tube, scenario.controller.horizon_steps)
assert margins == cert.margins
M = np.column_stack([getattr(cert.margins, k) for k in MARGIN_COLUMNS])
print(f"Cartesian one-period tube: p_xy = {tube.p_xy:.4f} m, p_z = {tube.p_z:.4f} m, psi = {tube.psi:.4f} rad")
print(f"{'arc j':>6} | " + " | ".join(f"{k:>8}" for k in MARGIN_COLUMNS) + " | e_d step = p_xy + u psi j delta")
for j, row in enumerate(M):
    step = "" if j == 0 else f"{M[j, 0] - M[j - 1, 0]:.4f} = {tube.p_xy + problem.u_max * tube.psi * j * problem.period:.4f}"
    print(f"{j:>6} | " + " | ".join(f"{x:8.4f}" for x in row) + f" | {step}")
print(f"e_o margin of the last arc {M[-1, 2]:.3f} < e_o_max {problem.e_o_max:g}: condition e_bar[e_o] holds")

# %% [markdown]
# The e_o margin grows fastest: a position offset Δp seen from the target at distance ≥ ε turns
# the bearing by up to asin(Δp/ε). This is the margin that stops larger σ in tutorial 03.
#
# ## Step 3: constraints between the nodes — the exact arc check
# The FHOCP enforces its constraints at the nodes t_k + jδ only (linearised, softened). The
# theorem needs them at *every* time. `check_plan` integrates the plan along its exact arcs
# (`plan_arcs`), evaluates every constraint at 11 points per arc, and tightens each one further by
# rate × spacing / 2 (with the certificate's bound on how fast that quantity can change along an
# arc): between two evaluated points nothing can move farther than that. So the check covers the
# whole arc.
#
# We build a plan by hand that passes every constraint **at its nodes** but **grazes** an
# obstacle between two of them. The vehicle drives straight (v̂ = (ū, 0, 0)) towards where the
# target will be, tangent to the obstacle's keep-out ball (obstacle radius + vehicle radius +
# M_pos,7) at the middle of the last arc. A straight chord cuts a circle between two points that
# lie on it, so the middle of the arc is closer than its ends.

# %%
obstacle = scenario.obstacles[0]
center, dt, n_arcs = np.asarray(obstacle.center), scenario.controller.dt, scenario.controller.horizon_steps
keep_out = obstacle.radius + scenario.vehicle_radius + M[:, 3]          # per arc (m)
u_hat = float(cert.v_bar[0])
t0 = 25.0 - 8.75                  # the target reaches the obstacle at t = 25 s; this plan is 8 s before
aim = scenario.trajectory.position(t0 + (n_arcs - 0.5) * dt)             # target at the middle of the last arc


def tangent_plan(offset):
    """x0 and inputs of a straight plan whose closest approach (mid last arc) is keep_out[-1] + offset."""
    d = keep_out[-1] + offset
    to_aim = aim[:2] - center[:2]
    angle = np.arctan2(to_aim[1], to_aim[0]) + np.arccos(d / np.linalg.norm(to_aim))
    closest = center[:2] + d * np.array([np.cos(angle), np.sin(angle)])
    psi = np.arctan2(*(aim[:2] - closest)[::-1])
    start = closest - (n_arcs - 0.5) * u_hat * dt * np.array([np.cos(psi), np.sin(psi)])
    return np.array([start[0], start[1], 0.0, psi]), np.tile([u_hat, 0.0, 0.0], (n_arcs, 1))


def clearance(x0, inputs, samples):
    """Distance to the obstacle's keep-out ball of each arc (m), (n_arcs, samples + 1)."""
    arcs = plan_arcs(x0, inputs, dt, samples)
    return np.linalg.norm(arcs[..., :3] - center, axis=-1) - keep_out[:, None], arcs


plans = {"grazing": tangent_plan(-1e-4), "3 mm wider": tangent_plan(3e-3)}
fine = 100 if QUICK else 400
for name, (x0, inputs) in plans.items():
    at_nodes, _ = clearance(x0, inputs, 1)
    on_arcs, arcs = clearance(x0, inputs, fine)
    nodes = np.vstack([arcs[:, 0], arcs[-1:, -1]])
    e = error_coordinates(nodes, scenario.trajectory.position(t0 + dt * np.arange(n_arcs + 1)))
    verdict = check_plan(scenario, cert.tightening, t0, x0, inputs, scenario.obstacles, sign=-1)
    print(f"{name:>10}: min clearance at the nodes {1e3 * at_nodes.min():+.3f} mm, along the arcs "
          f"{1e3 * on_arcs.min():+.3f} mm;  e_d {e[:, 0].min():.3f}..{e[:, 0].max():.3f} m, "
          f"|e_o| <= {np.abs(e[:, 2]).max():.3f}")
    print(f"{'':>12}check_plan: ok = {verdict.ok}, worst slack {1e3 * verdict.slack:+.2f} mm at '{verdict.where}'")

# %% [markdown]
# The grazing plan is clear at all nine nodes and cuts into the keep-out ball by 0.1 mm in the
# middle of its last arc: `check_plan` rejects it. At δ = 0.1 s an arc is only ū δ = 3.6 cm long,
# so what hides between the nodes is small here — but a proof about every t cannot ignore it.
# Note the worst slack, −2.6 mm: it includes the padding ‖ṗ‖ × spacing/2 = 0.5 m/s × 0.01 s / 2 =
# 2.5 mm that lets 11 points stand for the whole arc. A plan 3 mm wider passes. When the plan
# of a sample is rejected, the loop replays the last accepted one (step 2), and that is why the
# margins had to grow.
#
# ## Step 4: the Tightening handed to the FHOCP
# `cert.tightening` packs all of this into a `tubekit.tightening.Tightening`; it raises
# `verify.NotCertifiedError` for a certificate that does not hold (`cert.best_effort_tightening()`
# gives a best-effort tightening with `certified=False`, and no guarantee). Two layers:
#
# * the FHOCP's **node constraints** (`v_max`, `e_d_min`, `e_d_max`, `e_z_max`, `e_o_max`,
#   `obstacle_margin`): uniform over the horizon, the largest margin plus an inter-node allowance,
#   each keeping at least a quarter of R. They steer the solver; they prove nothing;
# * the certificate's **per-arc data** (`margins`, `rates`, `tube`, `region`, `disturbance`): what
#   `check_plan` accepts plans with and what the run's promises are measured against.

# %%
tight = cert.tightening
for f in dataclasses.fields(tight):
    value = getattr(tight, f.name)
    shown = np.array2string(np.asarray(value), precision=4, suppress_small=True, max_line_width=110)
    print(f"{f.name:>16} = {shown if np.ndim(value) < 2 else shown.replace(chr(10), chr(10) + ' ' * 19)}")
baseline = Tightening.untightened(scenario)      # the no-tube baseline: V itself, no arc check
print(f"horizon_arcs = {tight.horizon_arcs} (baseline: {baseline.horizon_arcs}, v_max = {baseline.v_max})")

# %% [markdown]
# ## The figure

# %%
plt.rcParams.update({"font.size": 11})
fig, axes = plt.subplots(2, 2, figsize=(14, 10), layout="constrained")

ax = axes[0, 0]                                 # inputs
names = ["u [m/s]", "w [m/s]", "r [rad/s]"]
y = np.arange(3)
ax.barh(y, cert.v_bar, color="tab:blue", label="V_bar: left for the nominal (FHOCP)")
ax.barh(y, cert.kappa_bar, left=cert.v_bar, color="tab:orange", label="kappa_bar: reserved for the feedback")
ax.plot(need, y, "kD", ms=8, label="necessary: keep_up[u], keep_up[w], yaw_budget")
for j in range(3):
    ax.text(V[j] + 0.008, j, f"V = {V[j]:g}", va="center", fontsize=10)
ax.set_yticks(y, names)
ax.set_xlim(0, 0.62)
ax.set_ylim(-0.5, 3.4)
ax.set_xlabel("input limit (units per row)")
ax.set_title("Step 1: V = V_bar + kappa_bar (never saturates)")
ax.legend(loc="upper left", fontsize=9, ncol=2)

ax = axes[0, 1]                                 # margins along the horizon
j = np.arange(len(M))
for k, (lab, col) in enumerate((("M_d (e_d) [m]", "tab:blue"), ("M_z (e_z) [m]", "tab:orange"),
                                ("M_o (e_o) [-]", "tab:purple"), ("M_pos (position) [m]", "tab:gray"))):
    ax.plot(j, M[:, k], "o-", color=col, lw=2, label=lab)
ax.axhline(problem.e_o_max, color="tab:purple", ls=":", lw=1.5, label=f"e_o_max = {problem.e_o_max:g}")
ax.set_xlabel("arc j of the plan (t_k + j delta to t_k + (j+1) delta)")
ax.set_ylabel("margin")
ax.set_ylim(0, 0.55)
ax.set_title("Step 2: per-arc margins grow (the replayed plan)")
ax.legend(loc="upper left", fontsize=9)
ax.grid(alpha=0.3)

ax = axes[1, 0]                                 # top view of the grazing plan
x0, inputs = plans["grazing"]
_, arcs = clearance(x0, inputs, fine)
path = arcs[..., :2].reshape(-1, 2)
nodes = np.vstack([arcs[:, 0, :2], arcs[-1:, -1, :2]])
ax.add_patch(Circle(center[:2], obstacle.radius, color="tab:red", alpha=0.7, label="obstacle"))
ax.add_patch(Circle(center[:2], keep_out[-1], fc="none", ec="tab:red", ls="--", lw=1.5,
                    label="keep-out of the last arc: + r_bar + M_pos,7"))
ax.plot(path[:, 0], path[:, 1], "-", color="k", lw=1.5, label="grazing plan (exact arcs)")
ax.plot(nodes[:, 0], nodes[:, 1], "o", color="tab:blue", ms=5, label="FHOCP nodes")
tt = np.linspace(t0, t0 + 12.0, 200)
target = scenario.trajectory.position(tt)
ax.plot(target[:, 0], target[:, 1], color="tab:orange", lw=1.5, label="target path (next 12 s)")
ax.plot(*scenario.trajectory.position(t0)[:2], "o", color="tab:orange", ms=8, label="target at t_k")
ax.plot(*aim[:2], "*", color="tab:orange", mec="k", ms=13, label="target when the plan ends (aimed at)")
ax.set_aspect("equal")
ax.set_xlim(1.9, 3.9); ax.set_ylim(-0.85, 1.75)
ax.set_xlabel("x [m]"); ax.set_ylabel("y [m]")
ax.set_title("Step 3: a hand-made plan, tangent to the keep-out ball")
ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=2, fontsize=9)

ax = axes[1, 1]                                 # clearance along the plan
colours = {"grazing": "tab:red", "3 mm wider": "tab:green"}
tau = np.linspace(0.0, 1.0, fine + 1)
for name, (x0, inputs) in plans.items():
    on_arcs, _ = clearance(x0, inputs, fine)
    at_nodes, _ = clearance(x0, inputs, 1)
    ok = check_plan(scenario, tight, t0, x0, inputs, scenario.obstacles, sign=-1).ok
    ax.plot((n_arcs - 1 + tau) * dt, 1e3 * on_arcs[-1], "-", color=colours[name], lw=2,
            label=f"{name}: exact arcs -> check_plan {'ACCEPTS' if ok else 'REJECTS'}")
    ax.plot([(n_arcs - 1) * dt, n_arcs * dt], 1e3 * at_nodes[-1], "o", color=colours[name], ms=8)
ax.axhline(0.0, color="k", lw=1)
ax.axhline(1e3 * 0.5 * dt / 10 * tight.rates[3], color="0.4", ls=":", lw=1.5,
           label="check_plan's padding (rate x spacing / 2)")
ax.set_xlim((n_arcs - 1.05) * dt, (n_arcs + 0.05) * dt)
ax.set_ylim(-0.5, 4.5)
ax.set_xlabel("time along the plan [s] (dots: the last arc's two nodes)")
ax.set_ylabel("clearance to the keep-out ball of arc 7 [mm]")
ax.set_title("Step 3: clear at the nodes, not between them (last arc)")
ax.legend(loc="upper right", fontsize=9)
ax.grid(alpha=0.3)
fig.savefig(FIGURES / "04_tightened_sets.png", dpi=100)
print("wrote", FIGURES / "04_tightened_sets.png")

# %% [markdown]
# What the figure shows:
#
# * **Top left.** Each input limit splits into V̄ (the FHOCP's) and κ̄ (the feedback's). The
#   black ticks are the necessary needs: V̄ must reach them, else no controller keeps up.
# * **Top right.** The margins of the replayed plan grow arc by arc; M_o stays below e_o_max,
#   which is condition `e_bar[e_o]`.
# * **Bottom.** The grazing plan (red) is clear at every node (dots above 0) but dips below 0
#   inside its last arc: rejected. Moved 3 mm out (green), it clears the padding and is accepted.
#
# Tutorial 05 solves the FHOCP with these sets; tutorial 06 closes the loop and measures every
# promise of the certificate on the run.
