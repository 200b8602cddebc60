# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # 07 — Property-based testing of your own controller
#
# A certificate is a proof on paper; a property test is an attempt to break it. The
# certificate (issue 11) is a *sampled-data* theorem: the nominal is reset to the measured
# state at every sample (ρ = e − ê = 0 at t_k), v̂ is held over the period, κ is held over
# each tick of the ancillary rate, and for every disturbance with ‖ω_xy‖ ≤ ω̄_xy,
# |ω_z| ≤ ω̄_z the deviation stays in the box max_j |ρ_j| / tube_j ≤ 1 for the whole period.
# `verify.falsify.strategies` generates exactly the starts of such a period (valid by construction,
# never filtered), `verify.falsify.invariance.one_period_ratio` runs the period with the loop's own
# plant and law, and `verify.falsify.one_period` hunts for a ratio above 1.
#
# We test three ancillary laws κ = −σ K(J) ρ: the paper's (K = I), tubekit's corrected
# law (K = J⁻¹), and "your own" — here a hand-made sign-flipped law K = sign(c)·I,
# which someone might propose after reading tutorial 02.

# %%
import os
import sys
from pathlib import Path

import matplotlib

if "ipykernel" not in sys.modules:  # a script draws off-screen; a notebook keeps its inline figures
    matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from hypothesis import given, settings

import verify
from tubekit import LAWS, AncillaryLaw
from verify.falsify import strategies as vs
from verify.falsify.one_period import falsify, falsify_closed_loop, search_space
from verify.falsify.invariance import one_period_ratio

QUICK = os.environ.get("TUBEKIT_QUICK") == "1"
FIGURES = (Path(os.environ["TUBEKIT_FIGURES"]) if "TUBEKIT_FIGURES" in os.environ
           else Path(__file__).resolve().parent / "figures")
FIGURES.mkdir(parents=True, exist_ok=True)

# %% [markdown]
# ## Your own law
# An `AncillaryLaw` needs a name, a map from the Jacobian J (…, 3, 3) to the gain K, and a
# description. c = J[0, 0] = cos(ψ − θ) tells the heading hemisphere.

# %%
def sign_flip_gain(J):
    c = J[..., 0, 0]
    return np.sign(c)[..., None, None] * np.broadcast_to(np.eye(3), J.shape)


mine = AncillaryLaw("sign-flip", sign_flip_gain, "kappa = -sigma sign(c) rho")

# %% [markdown]
# ## The set to test over: from a certificate
# We take the scenario the corrected law certifies (`verify.certifiable_scenario()`): its
# certificate gives the region, σ, the per-axis one-period tube, V̄, the disturbance bounds
# and Ē (the errors an accepted plan starts from).

# %%
scenario = verify.certifiable_scenario()
cert = verify.certify(scenario, "corrected")
space = search_space(scenario, "corrected", certificate=cert)
print(f"certified: {cert.certified}; sigma = {space.sigma:g} 1/s, tube = {np.round(space.tube, 6)}, "
      f"{space.ticks} ticks of {space.tick:g} s, V_bar = {np.round(space.v_bar, 4)}")
print(space.region.describe())

# %% [markdown]
# ## A property test, written like any other test
# `@given(vs.period_configurations(...))` draws starts of a period; the body states the
# property. Calling the decorated function runs hypothesis.

# %%
configs = vs.period_configurations(space.region, space.start, space.v_bar, space.omega_bar)
tube = np.asarray(space.tube)


def ratio(cfg, law):
    return one_period_ratio(cfg, law, space.sigma, tube, space.tick, space.ticks)


def invariance_property(law):
    @settings(max_examples=50 if QUICK else 300, derandomize=True, database=None, deadline=None)
    @given(configs)
    def prop(cfg):
        """Property: one period from the reset keeps max_j |rho_j| / tube_j <= 1."""
        assert ratio(cfg, law) <= 1.0
    return prop


for law in (LAWS["corrected"], LAWS["paper"], mine):
    try:
        invariance_property(law)()
        print(f"{law.name:>10}: property holds on every drawn configuration")
    except AssertionError:
        print(f"{law.name:>10}: property FAILS (hypothesis printed the shrunk example above)")

# %% [markdown]
# ## The falsifier: a concrete, shrunk counterexample
# `falsify` searches the same set with hypothesis (guided by `target`), then refines the
# worst case with a local optimiser, and hands back the configuration.

# %%
budget = 100 if QUICK else 500
results = {law.name: falsify(scenario, space=space, controller=law, budget=budget,
                             local_iterations=600 if QUICK else 3000)
           for law in (LAWS["corrected"], LAWS["paper"], mine)}
for name, res in results.items():
    print(f"--- {name}\n{res.summary()}")

# %% [markdown]
# ## How far from the edge?
# The histogram shows the one-period ratio over random starts for each law. Values right of
# one are violations.

# %%
rng = np.random.default_rng(0)
n = 400 if QUICK else 3000
units = rng.uniform(0, 1, (n, vs.PERIOD_DIM))
samples = [vs.period_configuration_from_unit(space.region, space.start, space.v_bar, space.omega_bar, u)
           for u in units]
fig, ax = plt.subplots(figsize=(8, 4.2))
for law in (LAWS["corrected"], LAWS["paper"], mine):
    vals = np.array([ratio(c, law) for c in samples])
    vals = np.minimum(vals, 5.0)  # diverging laws: clip for the plot
    ax.hist(vals, bins=60, alpha=0.55, label=f"{law.name}: {100 * np.mean(vals > 1):.0f}% > 1")
ax.axvline(1.0, color="k", lw=1)
ax.set_xlabel("max_j |rho_j| / tube_j over one period  (> 1: the tube is left)")
ax.set_ylabel("configurations")
ax.set_title(f"one-period tube, sigma = {space.sigma:g}")
ax.legend()
fig.tight_layout()
fig.savefig(FIGURES / "07_property_testing.png", dpi=110)
print("wrote", FIGURES / "07_property_testing.png")

# %% [markdown]
# ## The whole loop: disturbance sequences
# `falsify_closed_loop` runs `tubekit.loop.closed_loop.run_closed_loop` itself (FHOCP, plan check,
# reset, ZOH) from starts on the faces of Ē, with a greedy ω that pushes the largest
# |ρ_j| / tube_j at every tick and with piecewise-constant sequences tuned by a (1 + λ)
# evolution strategy, and checks every promise of the run. The largest ratio it finds is the
# certificate's tightness figure.

# %%
loop = falsify_closed_loop(scenario, "corrected", certificate=cert, budget=4 if QUICK else 20, duration=3.0)
print(loop.summary())

# %% [markdown]
# The corrected law never leaves the tube; on e_z (a linear axis) the one-period bound is
# exact, so the search reaches a ratio of 1 there. The paper's law leaves it as soon as the
# vehicle points at the target (its J K = J has a negative diagonal there, so the discrete
# loop amplifies ρ). The sign-flip law has the right sign, but its closed-loop gain sign(c) J
# is not the identity: the tube certified for the corrected law is too small for it. To
# certify your own law, give it a sympy `symbolic_gain` and pass it to `verify.certify`:
# tutorial 08 does that.
