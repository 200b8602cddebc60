# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # 08 — Certifying your own gains: the design search and the certifiable envelope
#
# Tutorial 03 showed that the paper's Section VI scenario does not certify, with either law.
# Here we ask the designer's question: *what would?* Two tools:
#
# * `verify.envelope(scenario, law)` searches, by bisection on certified / not certified, the
#   largest disturbance bound ω̄ and target speed that certify for a grid of ε (the smallest
#   allowed distance to the target), with everything else as in the scenario;
# * building variants by hand — `Scenario.with_changes(...)` for top-level fields and
#   `dataclasses.replace` for the nested settings — and certifying each one, to see which
#   condition blocks which design.

# %%
import dataclasses
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import ListedColormap

import verify
from tubekit import paper_scenario

QUICK = os.environ.get("TUBEKIT_QUICK") == "1"
FIGURES = Path(os.environ.get("TUBEKIT_FIGURES", Path(__file__).resolve().parent / "figures"))
FIGURES.mkdir(parents=True, exist_ok=True)

# %% [markdown]
# ## The envelope of the paper's scenario
# Every point of the search is a full certificate (bounds that do not depend on the varied
# quantity are cached, so a bisection step costs only the certificate's arithmetic).
# `quick=True` uses coarser grids and looser (still rigorous) bounds.

# %%
paper = paper_scenario()
env_paper = verify.envelope(paper, "corrected", quick=QUICK)
print(f"scenario: epsilon = {env_paper.epsilon:g} m, omega_bar = {env_paper.omega_bar:.4f} m/s, "
      f"target speed = {env_paper.speed:.4f} m/s, certified: {env_paper.certified_at_scenario}")
print(f"largest omega_bar at epsilon = {env_paper.epsilon:g} m: {env_paper.max_omega_bar}")
print(f"smallest epsilon at omega_bar = {env_paper.omega_bar:.4f} m/s: {env_paper.min_epsilon}")
print(f"largest target speed at the scenario's epsilon and omega_bar: {env_paper.max_speed}")
print("\nwhat fails, per epsilon (at the scenario's omega_bar and speed):")
for e, fails in zip(env_paper.eps_grid, env_paper.failures_by_eps):
    print(f"  epsilon = {e:6.4g} m: {', '.join(fails) or 'certified'}")

# %% [markdown]
# Nothing certifies, at any ε in the searched range, for any ω̄ ≥ 0 — at the paper's target
# speed. The failure lists say why: `keep_up_real[u]` and `keep_up_nominal[u]` fail at every ε.
# The target moves at 0.377 m/s and the vehicle's surge limit is 0.4 m/s; the remaining
# 0.023 m/s must pay for the current *and* for the tube feedback. The speed/disturbance
# trade-off at the paper's ε makes that concrete:

# %%
print(f"at epsilon = {env_paper.epsilon:g} m: target speed -> largest certifiable omega_bar")
for sp, w in zip(env_paper.speed_grid, env_paper.omega_max_by_speed):
    print(f"  {sp:8.5f} m/s -> {'none' if not np.isfinite(w) else f'{w:.5f} m/s'}")

# %% [markdown]
# At ε = 0.1 m only an (almost) stationary target certifies, and only against a current
# of about 2 mm/s. The envelope keeps the region's |e_o| ≤ 0.9; the corrected law's input use
# grows like 1/√(1 − e_o²), so let us also search with |e_o| ≤ 0.5:

# %%
paper_eo = paper.with_changes(region=dataclasses.replace(paper.region, e_o_max=0.5))
env_eo = verify.envelope(paper_eo, "corrected", quick=QUICK)
print(f"|e_o| <= 0.5: certified at the scenario: {env_eo.certified_at_scenario}; largest omega_bar for a "
      f"stationary target at epsilon = 0.1 m: {env_eo.omega_max_by_speed[0]:.5f} m/s; "
      "largest certifiable target speed there: "
      f"{env_eo.speed_grid[np.isfinite(env_eo.omega_max_by_speed)].max():.4f} m/s")

# %% [markdown]
# Better by a factor of three to four, still far from the paper's numbers. No single knob of the
# envelope is enough; we need to change several things at once.
#
# ## Variants by hand
# Starting from the paper's scenario with the corrected law, we change one thing at a time,
# then combine. Nested settings are frozen dataclasses: `dataclasses.replace` makes a
# modified copy, `Scenario.with_changes` puts it back.

# %%
def slower(s):            # target speed halved: circle rate pi/25 -> pi/50 (0.377 -> 0.1885 m/s)
    return s.with_changes(trajectory=dataclasses.replace(s.trajectory, rate=s.trajectory.rate / 2))


def weaker(s):            # current amplitude 0.1 -> 0.02 m/s per axis, sway bound 0.02 -> 0.005 m/s
    d = s.disturbance
    return s.with_changes(disturbance=dataclasses.replace(d, amplitude=(0.02, 0.02, 0.02),
                                                          sway=dataclasses.replace(d.sway, bound=0.005)))


def farther(s, move_start=True):   # epsilon 0.1 -> 0.5 m; the start e_d(0) = 0.5 m must move back
    s = s.with_changes(epsilon=0.5)
    return s.with_changes(initial_state=(-0.8, 3.0, 0.2, 0.0)) if move_start else s


def narrower(s):          # region |e_o| <= 0.9 -> 0.5
    return s.with_changes(region=dataclasses.replace(s.region, e_o_max=0.5))


def with_sigma(s, sigma):  # fix the ancillary gain instead of letting the verifier choose
    return s.with_changes(controller=dataclasses.replace(s.controller, sigma=sigma))


all_four = narrower(farther(weaker(slower(paper))))
variants = [
    ("paper scenario", paper, "corrected"),
    ("paper scenario, paper's law", paper, "paper"),
    ("slower target", slower(paper), "corrected"),
    ("weaker current", weaker(paper), "corrected"),
    ("eps = 0.5 m, start unchanged", farther(paper, move_start=False), "corrected"),
    ("eps = 0.5 m", farther(paper), "corrected"),
    ("|e_o| <= 0.5", narrower(paper), "corrected"),
    ("slower + weaker", weaker(slower(paper)), "corrected"),
    ("slower + weaker + eps", farther(weaker(slower(paper))), "corrected"),
    ("all four", all_four, "corrected"),
    ("all four, paper's law", all_four, "paper"),
    ("all four, sigma = 10", with_sigma(all_four, 10.0), "corrected"),
    ("all four, sigma = 1", with_sigma(all_four, 1.0), "corrected"),
    ("all four, sigma = 200", with_sigma(all_four, 200.0), "corrected"),
]
certs = [(name, verify.certify(s, law)) for name, s, law in variants]
print(f"{'variant':>30} | {'law':9} | {'cert.':5} | {'sigma':>6} | {'rho_tilde':>9} | blocked by (lhs vs rhs)")
for name, c in certs:
    sig = "-" if c.sigma["value"] is None else f"{c.sigma['value']:g}"
    rho = "-" if c.rho_tilde is None else f"{c.rho_tilde:.3g}"
    blocks = "; ".join(f"{f['condition']} {f['lhs']:.3g} vs {f['rhs']:.3g}" for f in c.failures) or "-"
    print(f"{name:>30} | {c.law:9} | {str(c.certified):5} | {sig:>6} | {rho:>9} | {blocks}")
print("\n'all four' is verify.certifiable_scenario():",
      all_four.with_changes(name="certifiable-corrected") == verify.certifiable_scenario())

# %% [markdown]
# Reading the table from the top:
#
# * Each single change shrinks ρ̃ and the input demand, but the tube feedback still needs
#   more surge, heave and yaw than the vehicle has (`v_bar[·]` negative), and at the paper's
#   target speed `keep_up_real[u]` fails on its own.
# * ε = 0.5 m helps most (ξ̄, L2 and the bearing fold all scale like 1/ε) — but only if the
#   start moves back too: the paper's start is 0.5 m behind the target, on the boundary of
#   the new region, and `initial` fails (e(0) must lie in Ē, i.e. e_d(0) ≥ ε + ρ̃).
# * Slower + weaker + ε leaves the yaw feedback (`v_bar[r]`) and the nominal's surge
#   (`keep_up_nominal[u]`); narrowing |e_o| fixes both — the certifiable scenario of
#   tutorials 03 and 04.
# * The paper's law fails J_lower even there: Remark 1 does not depend on the numbers.
# * σ matters: σ = 1 is below (L1 + L2)/J_lower = 1.88 (eq. sigma fails, nothing downstream
#   is evaluated); σ = 10 is admissible but the tube is wider and the nominal can no longer
#   keep up (tutorial 03: keep-up needs σ ≳ 16); σ = 200 gives the smallest tube but exceeds
#   the sampled-data limit f/sup‖JK‖ = 100 1/s of the 100 Hz ancillary loop (raise
#   `controller.ancillary_rate_hz` to allow it).

# %% [markdown]
# ## How much margin does the certified design have?
# The envelope of the certifiable scenario answers that.

# %%
easy = verify.certifiable_scenario()
env_easy = verify.envelope(easy, quick=QUICK)
print(f"largest omega_bar at epsilon = {env_easy.epsilon:g} m: {env_easy.max_omega_bar:.4f} m/s "
      f"(design: {env_easy.omega_bar:.4f})")
print(f"smallest epsilon at omega_bar = {env_easy.omega_bar:.4f} m/s: {env_easy.min_epsilon:.4f} m "
      f"(design: {env_easy.epsilon:g})")
print(f"largest target speed at the design's epsilon and omega_bar: {env_easy.max_speed:.4f} m/s "
      f"(design: {env_easy.speed:.4f})")
print(f"stationary target: largest omega_bar = {env_easy.omega_max_by_speed[0]:.4f} m/s")
print("\nper epsilon:")
def num(x):
    return f"{x:8.4g}" if np.isfinite(x) else f"{'-':>8}"


for e, w, sp, fails in zip(env_easy.eps_grid, env_easy.omega_max, env_easy.speed_max, env_easy.failures_by_eps):
    print(f"  epsilon = {e:6.4g} m: largest omega_bar {num(w)} m/s, largest speed {num(sp)} m/s | "
          f"{', '.join(fails) or 'certified'}")

# %% [markdown]
# The design sits close to its envelope: about 25 % more current or 6 % more target speed
# and it no longer certifies. Too small an ε blows up the tube (below ε ≈ 0.47 m the nominal
# cannot keep up). A somewhat larger ε has more room (ε ≈ 0.58 m certifies up to
# ω̄ ≈ 0.06 m/s), but too large an ε fails `initial` (the start e_d(0) = 0.8 m must lie in Ē)
# and then `terminal` (F needs ‖ê‖_P ≤ ε̄ somewhere with e_d ≥ ε + ρ̃).
# (`verify.plot_envelope(result, path)` draws the standard three-panel plot of one envelope,
# as `tubekit envelope --plot` does; below we overlay several.)
#
# ## The figures
# `08_envelope.png`: left, the speed/disturbance trade-off at each scenario's ε (paper,
# paper with |e_o| ≤ 0.5, certifiable) with the designs starred; middle, the certifiable
# scenario's (ε, ω̄) grid with its largest-ω̄ curve; right, the largest target speed per ε.

# %%
fig, axes = plt.subplots(1, 3, figsize=(17, 4.8), layout="constrained")
ax = axes[0]
for env, label, col in ((env_paper, "paper (eps 0.1 m, |e_o| <= 0.9)", "tab:red"),
                        (env_eo, "paper, |e_o| <= 0.5", "tab:orange"),
                        (env_easy, "certifiable (eps 0.5 m, |e_o| <= 0.5)", "tab:green")):
    ok = np.isfinite(env.omega_max_by_speed) & (env.omega_max_by_speed > 0)
    ax.plot(env.speed_grid[ok], env.omega_max_by_speed[ok], "o-", ms=3, color=col, label=label)
    if env is not env_eo:      # same design point as the paper's
        ax.plot([env.speed], [env.omega_bar], "*", ms=14, color=col, mec="k")
ax.set_yscale("log")
ax.set_ylim(1e-4, 0.5)
ax.set_xlabel("horizontal target speed (m/s)")
ax.set_ylabel("largest certifiable omega_bar (m/s)")
ax.set_title("certifiable below each curve (stars: the designs)")
ax.annotate(f"paper design ({env_paper.speed:.3g} m/s, {env_paper.omega_bar:.3g} m/s)",
            (env_paper.speed, env_paper.omega_bar), xytext=(0.2, 0.3), fontsize=8,
            arrowprops=dict(arrowstyle="->", color="0.3"))
ax.legend(fontsize=8, loc="lower right")

ax = axes[1]
E, W = np.meshgrid(env_easy.eps_grid, env_easy.omega_grid, indexing="ij")
g = env_easy.certified_grid
ax.scatter(E[g], W[g], s=14, c="tab:green", label="certified")
ax.scatter(E[~g], W[~g], s=8, c="lightgray", label="not certified")
ax.plot(env_easy.eps_grid, env_easy.omega_max, "-", color="tab:green", label="largest certifiable omega_bar")
ax.plot([env_easy.epsilon], [env_easy.omega_bar], "k*", ms=14, label="certifiable design")
ax.set_xscale("log")
ax.set_xlabel("epsilon = min e_d (m)")
ax.set_ylabel("omega_bar (m/s)")
ax.set_title(f"certifiable scenario: target speed {env_easy.speed:.3g} m/s")
ax.legend(fontsize=8)

ax = axes[2]
ax.plot(env_easy.eps_grid, env_easy.speed_max, "o-", color="tab:green", ms=4,
        label=f"certifiable scenario (omega_bar = {env_easy.omega_bar:.3g} m/s)")
ax.plot(env_paper.eps_grid, np.nan_to_num(env_paper.speed_max, nan=0.0), "x", color="tab:red",
        label=f"paper scenario (omega_bar = {env_paper.omega_bar:.3g} m/s): none")
ax.axhline(env_paper.speed, color="tab:red", ls="--", lw=1, label=f"paper's target speed {env_paper.speed:.3g} m/s")
ax.axhline(env_easy.speed, color="tab:green", ls="--", lw=1, label=f"certifiable design {env_easy.speed:.3g} m/s")
ax.set_xscale("log")
ax.set_xlabel("epsilon = min e_d (m)")
ax.set_ylabel("largest certifiable target speed (m/s)")
ax.set_title("largest target speed per epsilon (x: none certifies)")
ax.legend(fontsize=8)
fig.savefig(FIGURES / "08_envelope.png", dpi=110)
print("wrote", FIGURES / "08_envelope.png")

# %% [markdown]
# `08_variants.png`: every condition of every variant — green holds, red fails, grey not
# evaluated (needs ρ̃, which does not exist), white not checked for that variant
# (`sigma_sampled` appears only when σ is fixed).

# %%
columns = []
for _, c in certs:
    for cond in c.conditions:
        if cond.condition not in columns:
            columns.append(cond.condition)
state = np.full((len(certs), len(columns)), 3)         # 0 fail, 1 ok, 2 n/a, 3 not checked
for i, (_, c) in enumerate(certs):
    for cond in c.conditions:
        state[i, columns.index(cond.condition)] = {False: 0, True: 1, None: 2}[cond.ok]
fig, ax = plt.subplots(figsize=(14, 6.5), layout="constrained")
ax.imshow(state, cmap=ListedColormap(["tab:red", "tab:green", "0.75", "white"]), vmin=-0.5, vmax=3.5,
          aspect="auto")
for i in range(state.shape[0]):
    for j in range(state.shape[1]):
        ax.text(j, i, ("FAIL", "ok", "n/a", "")[state[i, j]], ha="center", va="center", fontsize=7,
                color="white" if state[i, j] == 0 else "k")
ax.set_xticks(range(len(columns)), columns, rotation=50, ha="right", fontsize=9)
ax.set_yticks(range(len(certs)), [f"{n}  [{'CERTIFIED' if c.certified else 'not certified'}]" for n, c in certs],
              fontsize=9)
ax.set_xticks(np.arange(-0.5, len(columns)), minor=True)
ax.set_yticks(np.arange(-0.5, len(certs)), minor=True)
ax.grid(which="minor", color="k", lw=0.5)
ax.tick_params(which="minor", length=0)
ax.set_title("which condition blocks which design (paper scenario + changes; corrected law unless noted)")
fig.savefig(FIGURES / "08_variants.png", dpi=110)
print("wrote", FIGURES / "08_variants.png")

# %% [markdown]
# To certify your own design: change the scenario (TOML or `with_changes`), run
# `verify.certify` (or `tubekit certify my.toml`), read the failed conditions' two sides, and
# use `verify.envelope` (`tubekit envelope my.toml`) to see how far each knob would have to move.
# Once it certifies, `certificate.tightening()` hands V̄, Ē and the obstacle margin to the
# FHOCP (tutorial 04).

# %% [markdown]
# ## Your own law, certified
# A law is κ = −σ K(J) ρ. Give it a numeric gain *and* the same map on a sympy Matrix
# (`symbolic_gain`): the verifier substitutes the derived J in polar form and bounds
# K(e) and J(e) K(e) with interval arithmetic, exactly as for the built-in laws. Here:
# K = diag(1/J₀₀, 1, 1/J₂₂) — it inverts only the diagonal of J.

# %%
import sympy as sp

from tubekit import AncillaryLaw


def diag_inverse(J):
    K = np.zeros_like(J)
    K[..., 0, 0] = 1.0 / J[..., 0, 0]
    K[..., 1, 1] = 1.0
    K[..., 2, 2] = 1.0 / J[..., 2, 2]
    return K


mine = AncillaryLaw("diag-inverse", diag_inverse, "kappa = -sigma diag(1/J00, 1, 1/J22) rho",
                    symbolic_gain=lambda J: sp.diag(1 / J[0, 0], 1, 1 / J[2, 2]))
for law in ("corrected", mine):
    c = verify.certify(verify.certifiable_scenario(), law)
    name = law if isinstance(law, str) else law.name
    print(f"{name:>12}: {'CERTIFIED' if c.certified else 'not certified'};  J_lower = {c.bounds['J_lower'].bound:.4g}, "
          f"rho_tilde = {c.rho['rho_tilde'] if c.rho['rho_tilde'] is not None else float('nan'):.4g}")
    for f in c.failures:
        print(f"{'':>14}FAIL {f['condition']}: {f['lhs']:.4g} vs {f['rhs']:.4g}")

# %% [markdown]
# Ignoring the coupling term −e_o c/e_d of J halves J_lower (1 − |e_o|/(2 e_d) ≥ 0.5 on this
# region instead of 1). Since σ J_lower − L1 − L2 is Lemma 1's denominator, ρ̃ grows about
# 3.5-fold (0.0016 → 0.0058 as printed above) and so does the input the tube reserves: the
# scenario that certifies with the inverse-Jacobian law fails here on the input conditions.
# The certificate names them with numbers, so you know which knob to turn.
