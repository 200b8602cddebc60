# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # 04 — Tightened sets and the terminal set, drawn
#
# Section V of the paper lets the FHOCP plan for the *nominal* system only, and makes room
# for the tube of tutorial 03 by shrinking its sets:
#
#     Ē = E ⊖ P,      V̄ = V ⊖ [−σ ∘ P],      F = {ê ∈ Ē : ‖ê‖_P ≤ ε̄},
#
# with P = {‖ρ‖ ≤ ρ̃} the tube. If the nominal stays in Ē and uses inputs in V̄, the real
# error e = ê + ρ stays in E and the real input v = v̂ + κ stays in V. On top of that the
# nominal *position* must keep a margin from the obstacles, because between two FHOCP samples
# the real vehicle drifts away from the nominal one.
#
# This tutorial takes all of these sets from a certificate and draws them: first for the
# scenario the corrected law certifies, then — side by side — the best-effort tightening of
# the paper's scenario, which is *not* certified and carries no guarantee.

# %%
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle, Rectangle

import verify
from tubekit import error_coordinates, paper_scenario

QUICK = os.environ.get("TUBEKIT_QUICK") == "1"
FIGURES = Path(os.environ.get("TUBEKIT_FIGURES", Path(__file__).resolve().parent / "figures"))
FIGURES.mkdir(parents=True, exist_ok=True)

# %% [markdown]
# ## The certified design
# `Certificate.tightening()` is the hand-off to the FHOCP: a `tubekit.tightening.Tightening`
# with V̄, the bounds of Ē, the obstacle margin, ρ̃ and σ. It raises `NotCertifiedError`
# unless every condition holds.

# %%
easy_scenario = verify.certifiable_scenario()
easy = verify.certify(easy_scenario)
tight = easy.tightening()
print(f"certified: {easy.certified}, law {easy.law!r}, sigma = {tight.sigma:g} 1/s, rho_tilde = {tight.rho_tilde:.5f}")
print(tight)

# %% [markdown]
# ## V̄: the nominal's input box
# The feedback κ = −σ J⁻¹ρ uses at most |κ_i| ≤ σ ρ̃ sup‖row_i K‖ of input i (`kappa_bar`).
# V̄ is V with that much removed from each side. The nominal must still be able to follow the
# target (keep-up): ū ≥ target speed.

# %%
V = np.array(easy.region.v_max)
for i, (ax, unit) in enumerate((("u", "m/s"), ("w", "m/s"), ("r", "rad/s"))):
    print(f"  |{ax}| <= {V[i]:g} {unit}  ->  |{ax}_hat| <= {tight.v_max[i]:.4f} {unit}  "
          f"(tightened by |kappa_{ax}| <= {easy.kappa_bar[i]:.4f}, {100 * easy.kappa_bar[i] / V[i]:.0f}% of the limit)")
print(f"keep-up: u_bar = {tight.v_max[0]:.4f} m/s >= target speed {easy.region.pd_dot_xy_max:.4f} m/s")

# %% [markdown]
# ## Ē = R ⊖ P: the region shrunk by the tube
# E here is the certificate's region R (the box every bound holds over; tutorial 03). A box
# minus a Euclidean ball of radius ρ̃ is the box shrunk by ρ̃ on every side. ρ̃ = 0.0016 is
# small: in the figure it needs a zoomed inset. In particular the nominal keeps
# e_d ≥ ε + ρ̃, the paper's "stay ε away from the target" plus the tube.

# %%
R = easy.region
for k in ("e_d", "e_z", "e_o"):
    lo, hi = getattr(R, k)
    print(f"  {k}: R = [{lo:+.4f}, {hi:+.4f}]   E_bar = [{easy.e_bar[k][0]:+.4f}, {easy.e_bar[k][1]:+.4f}]")
print(f"Tightening: e_d in [{tight.e_d_min:.4f}, {tight.e_d_max:.4f}], |e_z| <= {tight.e_z_max:.4f}, "
      f"|e_o| <= {tight.e_o_max:.4f}")

# %% [markdown]
# ## The terminal set F
# F = {ê ∈ Ē : ‖ê‖_P ≤ ε̄} with P = diag(`controller.P`) and ε̄ = `controller.terminal_level`.
# The certificate checks that F is non-empty: the smallest ‖ê‖_P over Ē (at e_d = ε + ρ̃,
# e_z = e_o = 0) must not exceed ε̄. (It does not check that F is invariant — that is an
# assumption it lists.) Because ê = 0 is excluded (e_d ≥ ε), F is the part of the ellipsoid
# ‖ê‖_P ≤ ε̄ beyond the plane e_d = ε + ρ̃ (and inside the rest of Ē).

# %%
P = np.array(easy.terminal["P"])
level = easy.terminal["level"]
print(f"P = diag{tuple(float(x) for x in P)}, terminal level = {level:g}; "
      f"min over E_bar of ||e||_P = {easy.terminal['min_norm_P_over_E_bar']:.4f} <= {level:g}: {easy.terminal['ok']}")
print(f"F reaches e_d <= {level / np.sqrt(P[0]):.4f} m (at e_z = e_o = 0)")

# %% [markdown]
# ## The obstacle margin
# The nominal is reset to the measured state every δt, and in between the real position p
# drifts from the nominal p̂ by at most δt(√((κ̄_u + ū κ̄_r δt/2)² + κ̄_w²) + ω̄)
# (`obstacle_margin`). The FHOCP keeps p̂ at least vehicle radius + margin outside each
# obstacle; the certificate also re-checks the paper's obstacle separation (eq. obstacle_dis)
# with the inflated radii.

# %%
r_bar = easy_scenario.vehicle_radius
print(f"vehicle radius {r_bar:g} m + margin {easy.obstacle_margin:.4f} m")
for o in easy_scenario.obstacles:
    print(f"  obstacle at {o.center[:2]}, radius {o.radius:g} m: the nominal keeps its centre "
          f"{o.radius + r_bar + easy.obstacle_margin:.4f} m away")
for c in easy.conditions:
    if c.condition.startswith("obstacles"):
        print(f"  {c.condition}: {c.inequality}: {c.lhs:.4g} vs {c.rhs:.4g}")

# %% [markdown]
# ## The paper's scenario: a best-effort tightening, no guarantee
# The paper's scenario does not certify (tutorial 03), so `tightening()` refuses:

# %%
paper = paper_scenario()
hard = verify.certify(paper)                                  # the scenario's law: corrected
try:
    hard.tightening()
except verify.NotCertifiedError as exc:
    print("NotCertifiedError:", exc)

# %% [markdown]
# `tightening(allow_uncertified=True)` still returns *something* the FHOCP can run with, built
# by documented rules, not by the proof: state margin min(ρ̃, ε, a quarter of the narrowest
# region width), input tightening capped so that V̄ keeps at least half of V and the keep-up
# speed, obstacle margin capped at the vehicle radius, σ the admissible one if any, else
# `controller.sigma`, else 1 1/s. Compare what the certificate asked for with what the
# best-effort sets use:

# %%
best = hard.tightening(allow_uncertified=True)
print(best)
print(f"certificate asked for: rho_tilde = {hard.rho_tilde:.4f}, |kappa| <= {np.round(hard.kappa_bar, 2)} "
      f"(V = {list(hard.region.v_max)})")
print(f"best effort uses:      rho = {best.rho_tilde:.4f}, V_bar = {np.round(best.v_max, 4)}, "
      f"obstacle margin {best.obstacle_margin:.4f} m, sigma = {best.sigma:g}")
best_paper_law = verify.certify(paper, "paper").tightening(allow_uncertified=True)
print(f"with the paper's law:  rho = {best_paper_law.rho_tilde:.4f}, V_bar = {np.round(best_paper_law.v_max, 4)}, "
      f"sigma = {best_paper_law.sigma:g} (no admissible sigma: the fallback)")

# %% [markdown]
# The best-effort V̄ keeps 0.377 m/s of surge because the target moves at 0.377 m/s — while
# the certificate says the feedback alone would need 43 m/s. These sets are a reasonable
# engineering guess; nothing says the real error stays in R or the real input in V.
#
# ## The figure
# Top row: the certified design. Bottom row: the paper scenario's best-effort tightening
# (red title: no guarantee). Columns: V and V̄ in the (u, r) and (u, w) planes; R, Ē and F in
# the (e_d, e_o) plane at e_z = 0 and the (e_d, e_z) plane at e_o = 0 (since 0 lies in Ē's
# e_z and e_o ranges, these slices of F are also its projections); the workspace seen from
# above at t = 0.

# %%
def draw_inputs(ax, V, Vbar, i, j, names, speed):
    ax.add_patch(Rectangle((-V[i], -V[j]), 2 * V[i], 2 * V[j], fc="0.9", ec="k", label="V (vehicle limits)"))
    ax.add_patch(Rectangle((-Vbar[i], -Vbar[j]), 2 * Vbar[i], 2 * Vbar[j], fc="tab:blue", alpha=0.5, ec="tab:blue",
                           label="V_bar (nominal, FHOCP)"))
    if i == 0:
        ax.axvline(speed, color="tab:orange", ls="--", lw=1.2, label=f"target speed {speed:.3g} m/s")
    ax.set_xlim(-1.15 * V[i], 1.15 * V[i]); ax.set_ylim(-1.15 * V[j], 1.45 * V[j])
    ax.set_xlabel(names[0]); ax.set_ylabel(names[1])
    ax.legend(fontsize=7, loc="upper left")


def terminal_boundary(P, level, axis, grid):
    """e_d on the boundary of {||e||_P <= level} in the (e_d, e_axis) plane, other coordinate 0."""
    return np.sqrt(np.clip((level**2 - P[axis] * grid**2) / P[0], 0.0, None))


def draw_errors(ax, region, tight, P, level, axis, e0, zoom=None):
    name = ("e_d", "e_z", "e_o")[axis]
    lo, hi = getattr(region, name)
    half = tight.e_z_max if axis == 1 else tight.e_o_max
    for a in ([ax] + ([zoom] if zoom is not None else [])):
        a.add_patch(Rectangle((region.e_d[0], lo), region.e_d[1] - region.e_d[0], hi - lo, fc="0.9", ec="k",
                              label="R (bounds hold here)"))
        a.add_patch(Rectangle((tight.e_d_min, -half), tight.e_d_max - tight.e_d_min, 2 * half, fc="tab:blue",
                              alpha=0.35, ec="tab:blue", label="E_bar = R ⊖ P"))
        g = np.linspace(-half, half, 400)
        ed_f = np.minimum(terminal_boundary(P, level, axis, g), tight.e_d_max)
        a.fill_betweenx(g, tight.e_d_min, ed_f, where=ed_f > tight.e_d_min, color="tab:green", alpha=0.6,
                        label=f"F = {{||e||_P <= {level:g}}} ∩ E_bar")
        a.plot(e0[0], e0[axis], "k*", ms=10, label="e(0)")
    ax.set_xlim(0, region.e_d[1] * 1.05)
    ax.set_ylim(lo * 1.1, hi * 1.45)
    ax.set_xlabel("e_d (m)"); ax.set_ylabel(name + (" (m)" if axis == 1 else " = sin(psi - theta)"))
    ax.legend(fontsize=7, loc="upper right")


def draw_workspace(ax, scenario, region, tight, zoom=None):
    t = np.linspace(0, 2 * np.pi / abs(scenario.trajectory.rate), 400)
    path = scenario.trajectory.position(t)
    pd0 = scenario.trajectory.position(0.0)
    x0 = np.array(scenario.initial_state)
    r_bar = scenario.vehicle_radius
    for a in ([ax] + ([zoom] if zoom is not None else [])):
        a.plot(path[:, 0], path[:, 1], color="tab:orange", lw=1, label="target path p_d(t)")
        for k, o in enumerate(scenario.obstacles):
            a.add_patch(Circle(o.center[:2], o.radius + r_bar + tight.obstacle_margin, fc="tab:red", alpha=0.25,
                               ec="tab:red", lw=0.8,
                               label="obstacle + r_bar + margin (keep-out of p_hat)" if k == 0 else None))
            a.add_patch(Circle(o.center[:2], o.radius + r_bar, fc="none", ec="tab:red", ls="--", lw=0.8,
                               label="obstacle + r_bar (keep-out of p)" if k == 0 else None))
            a.add_patch(Circle(o.center[:2], o.radius, fc="tab:red", alpha=0.8, label="obstacle" if k == 0 else None))
        a.add_patch(Circle(pd0[:2], tight.e_d_min, fc="tab:blue", alpha=0.3, ec="tab:blue",
                           label=f"e_d < eps + rho = {tight.e_d_min:.4g} m (excluded)"))
        a.add_patch(Circle(pd0[:2], tight.e_d_max, fc="none", ec="tab:blue", ls=":",
                           label=f"e_d = e_d_max - rho = {tight.e_d_max:.4g} m"))
        a.add_patch(Circle(x0[:2], scenario.sensing_range, fc="none", ec="0.4", ls="-.", lw=0.8,
                           label=f"sensing range {scenario.sensing_range:g} m"))
        a.plot(*pd0[:2], "o", color="tab:orange", label="target at t = 0")
        a.annotate("", xy=x0[:2] + 0.5 * np.array([np.cos(x0[3]), np.sin(x0[3])]), xytext=x0[:2],
                   arrowprops=dict(arrowstyle="->", color="k"))
        a.plot(*x0[:2], "k.", label="vehicle at t = 0 (arrow: heading)")
    ax.set_aspect("equal"); ax.set_xlim(-4.2, 4.2); ax.set_ylim(-3.6, 6.4)
    ax.set_xlabel("x (m)"); ax.set_ylabel("y (m)")
    ax.legend(fontsize=7.5, loc="upper left", bbox_to_anchor=(1.02, 1.0))


def inset(ax, xlim, ylim, where):
    z = ax.inset_axes(where)
    z.set_xlim(*xlim); z.set_ylim(*ylim)
    z.tick_params(labelsize=6)
    ax.indicate_inset_zoom(z, edgecolor="0.3")
    return z


rows = [(easy_scenario, easy, tight, "certified (corrected law)", "k"),
        (paper, hard, best, "paper scenario, BEST EFFORT: no guarantee", "tab:red")]
fig, axes = plt.subplots(2, 5, figsize=(26, 10), layout="constrained",
                         gridspec_kw=dict(width_ratios=[1, 1, 1.15, 1.15, 1.9]))
for row, (scen, cert, tg, label, tcol) in enumerate(rows):
    V = np.array(cert.region.v_max)
    speed = cert.region.pd_dot_xy_max
    e0 = error_coordinates(np.array(scen.initial_state), scen.trajectory.position(0.0))
    P = np.array(scen.controller.P)
    level = scen.controller.terminal_level
    ax = axes[row, 0]
    draw_inputs(ax, V, tg.v_max, 0, 2, ("u (m/s)", "r (rad/s)"), speed)
    ax.set_title(f"{label}\ninputs (u, r)", color=tcol, fontsize=10)
    ax = axes[row, 1]
    draw_inputs(ax, V, tg.v_max, 0, 1, ("u (m/s)", "w (m/s)"), speed)
    ax.set_title(f"inputs (u, w); sigma = {tg.sigma:g} 1/s", fontsize=10)
    small = tg.rho_tilde < 0.02
    for col, axis in ((2, 2), (3, 1)):
        ax = axes[row, col]
        name = ("e_d", "e_z", "e_o")[axis]
        hi = getattr(cert.region, name)[1]
        z = None
        if small:     # zoom into the corner (epsilon, upper bound) so that rho_tilde is visible
            w = 8 * tg.rho_tilde
            z = inset(ax, (cert.region.e_d[0] - w / 2, cert.region.e_d[0] + w),
                      (hi - w, hi + w / 2), [0.5, 0.08, 0.45, 0.4])
            z.set_title(f"zoom: rho_tilde = {tg.rho_tilde:.2g}", fontsize=7)
        draw_errors(ax, cert.region, tg, P, level, axis, e0, zoom=z)
        other = "e_z" if axis == 2 else "e_o"
        ax.set_title(f"(e_d, {name}) at {other} = 0; state margin {tg.rho_tilde:.3g}", fontsize=10)
    ax = axes[row, 4]
    o = scen.obstacles[0]
    r_out = o.radius + scen.vehicle_radius + tg.obstacle_margin
    z = inset(ax, (o.center[0] - r_out - 0.06, o.center[0] - r_out + 0.1), (-0.08, 0.08), [0.29, 0.12, 0.42, 0.33])
    z.set_title(f"zoom: margin {tg.obstacle_margin:.3g} m", fontsize=7)
    draw_workspace(ax, scen, cert.region, tg, zoom=z)
    ax.set_title(f"workspace, top view, t = 0 ({scen.name})", fontsize=10)
fig.savefig(FIGURES / "04_tightened_sets.png", dpi=100)
print("wrote", FIGURES / "04_tightened_sets.png")

# %% [markdown]
# What the figure shows:
#
# * **Inputs.** Certified: V̄ keeps about half of every input, and the surge limit ū = 0.21 m/s
#   sits just right of the target speed (dashed) — keep-up is the tightest condition. Best
#   effort: V̄ is simply capped at half of V or the target speed; the feedback's real need
#   (43 m/s surge, 408 rad/s yaw) is ignored.
# * **Errors.** Certified: Ē is R shrunk by 0.0016 (visible only in the zoom); F is the part of
#   Ē with e_d up to 0.89 m, and e(0) = [0.8, 0.2, 0] starts in Ē. Best effort: the state
#   margin is ε = 0.1, not the certificate's ρ̃ = 0.19 — another cap.
# * **Workspace.** The nominal keeps out of each obstacle by obstacle radius + vehicle radius +
#   margin (0.029 m certified, zoom) and out of the disk e_d < ε + ρ̃ around the target.
#
# Only the top row comes with a proof; the bottom row is what you run when you want to try
# the paper's setup anyway. Tutorial 08 shows how to move a design from the bottom row to the top.
