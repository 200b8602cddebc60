# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # 01 — The vehicle and its kinematics
#
# The paper's AUV (eq. 11) has state **x = [x, y, z, ψ]** and input **v = [u, w, r]**
# (surge, heave, yaw rate). It has no sway thruster: it cannot push itself sideways.
# Whatever sideways velocity it has — the *sway* v_s — and the ocean current δ enter as a
# disturbance ω = δ + v_s[−sin ψ, cos ψ, 0]:
#
#     ẋ = u cos ψ + ω₁,   ẏ = u sin ψ + ω₂,   ż = w + ω₃,   ψ̇ = r.
#
# This tutorial drives the model open loop and draws what underactuation and sway mean.

# %%
import os
import sys
from pathlib import Path

import matplotlib

if "ipykernel" not in sys.modules:  # a script draws off-screen; a notebook keeps its inline figures
    matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from tubekit import Disturbance, SwayModel, kinematics, nominal_kinematics, paper_scenario
from tubekit.plant.kinematic import Plant

QUICK = os.environ.get("TUBEKIT_QUICK") == "1"
FIGURES = (Path(os.environ["TUBEKIT_FIGURES"]) if "TUBEKIT_FIGURES" in os.environ
           else Path(__file__).resolve().parent / "figures")
FIGURES.mkdir(parents=True, exist_ok=True)

# %% [markdown]
# ## Integrating the kinematics
# A fixed-step RK4 integrator is enough for a drawing; `tubekit.kinematics` is vectorised,
# so one call can advance several vehicles at once.

# %%
def rk4(f, x0, t_end, dt):
    xs, x, t = [x0], x0.copy(), 0.0
    while t < t_end - 1e-12:
        k1 = f(t, x); k2 = f(t + dt / 2, x + dt / 2 * k1)
        k3 = f(t + dt / 2, x + dt / 2 * k2); k4 = f(t + dt, x + dt * k3)
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4); t += dt
        xs.append(x)
    return np.array(xs)


t_end, dt = (20.0, 0.1) if QUICK else (40.0, 0.02)
v_turn = np.array([0.4, 0.0, 0.2])  # surge 0.4 m/s, yaw rate 0.2 rad/s: a circle of radius 2 m
x0 = np.zeros(4)

nominal = rk4(lambda t, x: nominal_kinematics(x, v_turn), x0, t_end, dt)

sway = SwayModel(gain=0.5, amplitude=0.0, bound=0.1)  # exaggerated side-slip to make it visible
sway_only = Plant(Disturbance(amplitude=(0.0, 0.0, 0.0), sway=sway))  # eq. (11) with sway alone
with_sway = rk4(lambda t, x: sway_only.rhs(t, x, v_turn), x0, t_end, dt)

dist = paper_scenario().disturbance  # the paper's current, 0.1 m/s amplitude, 15 s period
plant = Plant(dist)
with_current = rk4(lambda t, x: kinematics(x, v_turn, plant.current(t)), x0, t_end, dt)

print(f"after {t_end:g} s: nominal ends at {nominal[-1, :2].round(2)}, "
      f"with sway at {with_sway[-1, :2].round(2)}, with current at {with_current[-1, :2].round(2)}")
print(f"paper's disturbance bound omega_bar = {dist.omega_bar:.4f} m/s (current {dist.current_bound:.4f} "
      f"+ sway {dist.sway.bound:.3f})")

# %% [markdown]
# ## Underactuation: the velocity always points along the heading (without disturbance)
# The nominal velocity f(x)v = [u cos ψ, u sin ψ, w, r] has no component across the
# heading, whatever v is. We check it on random states and inputs:

# %%
rng = np.random.default_rng(0)
xs = rng.uniform(-5, 5, (1000, 4))
vs = rng.uniform(-1, 1, (1000, 3))
vel = nominal_kinematics(xs, vs)
lateral = -np.sin(xs[:, 3]) * vel[:, 0] + np.cos(xs[:, 3]) * vel[:, 1]
print(f"max |lateral velocity| of the nominal model over 1000 random points: {np.abs(lateral).max():.2e} m/s")

# %%
fig, axes = plt.subplots(1, 2, figsize=(11, 4.8))
ax = axes[0]
ax.plot(nominal[:, 0], nominal[:, 1], label="nominal (no disturbance)")
ax.plot(with_sway[:, 0], with_sway[:, 1], label="with side-slip (sway)")
ax.plot(with_current[:, 0], with_current[:, 1], label="with the paper's current")
for k in range(0, len(nominal), max(1, len(nominal) // 12)):
    x, y, _, psi = nominal[k]
    ax.arrow(x, y, 0.3 * np.cos(psi), 0.3 * np.sin(psi), head_width=0.1, color="k")
ax.set_aspect("equal"); ax.set_xlabel("x (m)"); ax.set_ylabel("y (m)")
ax.set_title("u = 0.4 m/s, r = 0.2 rad/s: arrows show heading")
ax.legend(loc="lower right", fontsize=8)

ax = axes[1]
# Try to move sideways: the best a surge/yaw vehicle can do is turn first.
turn_then_go = rk4(lambda t, x: nominal_kinematics(x, np.array([0.0 if t < np.pi else 0.4, 0.0,
                                                                  0.5 if t < np.pi else 0.0])),
                   np.zeros(4), 10.0, 0.02)
arc_then_go = rk4(lambda t, x: nominal_kinematics(x, np.array([0.4, 0.0, 0.5 if t < np.pi else 0.0])),
                  np.zeros(4), 10.0, 0.02)
ax.plot(turn_then_go[:, 0], turn_then_go[:, 1], label="turn in place (r = 0.5 rad/s), then surge")
ax.plot(arc_then_go[:, 0], arc_then_go[:, 1], label="surge 0.4 m/s while turning, then straight")
ax.annotate("", xy=(0, 2), xytext=(0, 0), arrowprops=dict(arrowstyle="->", color="r"))
ax.text(0.05, 1.0, "sideways: not possible\ndirectly (no sway thruster)", color="r", fontsize=8)
ax.set_aspect("equal"); ax.set_xlim(-1, 3); ax.set_ylim(-0.5, 4.5)
ax.set_xlabel("x (m)"); ax.set_ylabel("y (m)"); ax.set_title("reaching a point to the side")
ax.legend(loc="lower right", fontsize=8)
fig.tight_layout()
fig.savefig(FIGURES / "01_kinematics.png", dpi=110)
print("wrote", FIGURES / "01_kinematics.png")
