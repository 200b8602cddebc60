# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # 02 — Deriving the error dynamics with sympy, and auditing the paper
#
# The controller works on the error **e = [e_d, e_z, e_o]** (eqs. 12–14):
# e_d = ‖(e_x, e_y)‖ is the horizontal distance to the target, e_z the depth error and
# e_o = (e_x sin ψ − e_y cos ψ)/e_d = sin(ψ − θ) an orientation error, with
# θ = atan2(e_y, e_x) the bearing of the vehicle seen from the target.
#
# The paper prints ė = J v + ζ + ξ (eq. 18). Here we derive it instead of typing it in,
# and compare.

# %%
import os
import sys
from pathlib import Path

import matplotlib

if "ipykernel" not in sys.modules:  # a script draws off-screen; a notebook keeps its inline figures
    matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import sympy as sp

from tubekit.paper.audit import audit
from tubekit.model.derivation import derive
from tubekit.model.errors import numeric

QUICK = os.environ.get("TUBEKIT_QUICK") == "1"
FIGURES = (Path(os.environ["TUBEKIT_FIGURES"]) if "TUBEKIT_FIGURES" in os.environ
           else Path(__file__).resolve().parent / "figures")
FIGURES.mkdir(parents=True, exist_ok=True)

# %% [markdown]
# ## The derivation
# `derive()` differentiates e along eq. (11) and splits the result: J = ∂ė/∂v,
# ζ = ė with v = 0 and ω = 0, ξ = ė with v = 0 and ṗ_d = 0. The residual
# ė − (J v + ζ + ξ) is simplified to zero, so the split is exact.

# %%
d = derive()
print("J =")
sp.pprint(d.J)
print("residual:", list(d.residual))

# %% [markdown]
# ## The audit
# Each of the 15 printed terms is compared with the derivation: symbolically (polar form)
# and numerically at random points in both heading hemispheres, e_d down to 1e-6 m.

# %%
report = audit(samples=300 if QUICK else 3000, hemisphere_samples=200 if QUICK else 2000)
print(report.table())

# %% [markdown]
# Four printed terms are wrong: the third rows of J, ζ and ξ. By hand: the numerator of
# e_o, a = e_x sin ψ − e_y cos ψ, has ȧ = (ω₁ − ẋ_d) sin ψ − (ω₂ − ẏ_d) cos ψ + r(e_x cos ψ + e_y sin ψ):
# the surge u cancels, so u enters ė_o only through ė_d, and r's coefficient is
# c = cos(ψ − θ), not e_x e_y/e_d².
#
# ## Remark 1, checked
# With c = cos(ψ − θ), the derived J is [[c,0,0],[0,1,0],[−e_o c/e_d,0,c]]. We map
# λ_min of its symmetric part over (ψ − θ, e_d). The paper's Remark 1 claims it is
# positive on the whole feasible set.

# %%
n = 120 if QUICK else 400
phi = np.linspace(-np.pi, np.pi, n)                 # heading relative to the bearing
e_d = np.geomspace(0.05, 5.0, n)
PHI, ED = np.meshgrid(phi, e_d)
J = numeric().J(ED, np.zeros_like(ED), PHI)         # bearing 0: e_x = e_d, e_y = 0, psi = phi
lam = np.linalg.eigvalsh(0.5 * (J + np.swapaxes(J, -1, -2)))[..., 0]
toward = np.cos(PHI) < 0
print(f"lambda_min < 0 at {100 * np.mean(lam[toward] < 0):.1f}% of the 'toward' grid "
      f"and {100 * np.mean(lam[~toward] < 0):.1f}% of the 'away' grid")

fig, ax = plt.subplots(figsize=(7.5, 4.5))
lim = np.percentile(np.abs(lam), 95)
pc = ax.pcolormesh(PHI, ED, lam, cmap="RdBu", vmin=-lim, vmax=lim, shading="auto")
ax.contour(PHI, ED, lam, levels=[0.0], colors="k", linewidths=1)
ax.axvline(np.pi / 2, color="gray", ls=":"); ax.axvline(-np.pi / 2, color="gray", ls=":")
ax.set_yscale("log")
ax.set_xlabel("psi - bearing (rad)   [|.| > pi/2: vehicle points at the target ('toward')]")
ax.set_ylabel("e_d (m)")
ax.set_title("lambda_min((J+J^T)/2) of the derived J  (black: zero level)")
fig.colorbar(pc, ax=ax)
fig.tight_layout()
fig.savefig(FIGURES / "02_remark1.png", dpi=110)
print("wrote", FIGURES / "02_remark1.png")

# %% [markdown]
# Red is negative. The whole 'toward' half — the vehicle chasing the target, i.e. normal
# tracking — is red, and so is part of 'away' at small e_d. Remark 1 is false, and with it
# the proof of Lemma 1 for the paper's law κ = −σ(e − ê). Tutorial 03 shows what the
# verifier makes of that, and the corrected law that fixes it.
