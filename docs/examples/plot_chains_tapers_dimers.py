"""
Tapered chains, dimers and trimers
==================================

Chains whose grains change along the chain, all struck at 1 m/s without
precompression:

* **tapered** — each grain's mass q times the previous one's (same material, radii
  by q^{1/3}).  Forward (q < 1, large to small grains) the wave speeds up while its
  force drops (Sen, Manciu & Wright, Phys. Rev. E 57 (1998) 2386; Doney & Sen, Phys.
  Rev. Lett. 97 (2006) 155502); backward (q > 1) it slows down and breaks into a
  train.  For a slow taper the wave is, grain by grain, the exact solitary wave of the
  local grains carrying the energy it entered with
  (:func:`theory.tapers.adiabatic_taper_wave`);
* **dimer** — a unit cell of a heavy and a light grain of the same material (mass
  ratio 0.5) behind a uniform section (Jayaprakash, Starosvetsky & Vakakis, Phys. Rev.
  E 83 (2011) 036606), and a **trimer** whose cell has a softer, lighter grain and a
  smaller one.  Over many cells the wave travels at the Nesterenko speed of the
  homogenised cell at its peak contact force
  (:func:`theory.dimers.cell_solitary_speed`; Porter et al., Phys. Rev. E 77 (2008)
  015601).

The shipped scenarios ``chain_tapered``, ``chain_tapered_backward``, ``chain_dimer``
and ``chain_trimer``, each run by the three models through
:func:`hertzchain.compare.compare`: the discrete chain, the long-wave continuum (Eq. 7
on the chain's own per-grain coefficients, :class:`theory.medium.Medium`) and the
theory above; then ``chain_tapered_bca``, the growth of the wave along a slow taper
against the binary-collision approximation (Harbola, Rosas, Esposito & Lindenberg,
Phys. Rev. E 80 (2009) 031303; docs/physics.md §12).  Grains are counted from 0, as
everywhere in hertzchain.
"""

import matplotlib.pyplot as plt
import numpy as np

from hertzchain.compare import compare
from hertzchain.plotting import plot_profiles

names = ("chain_tapered", "chain_tapered_backward", "chain_dimer", "chain_trimer")
runs = {name: compare(name, progress=False) for name in names}

# %%
# Top: the grain velocities of the discrete chain and the continuum when the leading
# wave is last seen in the grains the theory describes, before any wave reaches the
# far end (dotted: where the profiled section starts).  Bottom: the position of the
# leading wave's peak against time, sampled on both models, and the theory's
# trajectory from the first sample in those grains (for the taper with the energy of
# the peak velocity the chain had there, for the cells at the peak contact force of
# the section, from the recorded strain maxima).


def theory_window(cmp):
    """Samples whose leading peak lies in the grains the chain's theory describes."""
    ct = cmp.run.theory.chain_theory
    x = cmp.series["discrete"].fronts[ct.front]
    ends = cmp.times < cmp.run.discrete.summary.get("t_end_reached", np.inf)
    return np.flatnonzero(np.isfinite(x) & ends & (x >= ct.first) & (x <= ct.last - 3))


def theory_trajectory(cmp, window):
    """Times (s) and positions (grains) of the leading peak by the chain's theory."""
    res = cmp.run
    ct = res.theory.chain_theory
    x = cmp.series["discrete"].fronts[ct.front]
    a, b = x[window[0]], x[window[-1]]
    vmax = res.simulation.record.vmax
    force = np.nan
    if ct.kind == "periodic":  # the largest contact force the section carried, N
        n, rmax = ct.params["exponent"], res.simulation.record.overlap_max
        contacts = slice(ct.first + 1, ct.last)
        force = float(np.max(res.chain.k[contacts] * np.maximum(rmax[contacts], 0) ** n))
    xs = np.linspace(a, b, 50)
    dt = [ct.travel_time(a, xb, float(vmax[int(a) - 1]), force) for xb in xs]
    return cmp.times[window[0]] + np.asarray(dt), xs


fig, axes = plt.subplots(2, 4, figsize=(13, 6))
for col, (name, cmp) in enumerate(runs.items()):
    res = cmp.run
    ct = res.theory.chain_theory
    window = theory_window(cmp)
    i = window[-1]
    plot_profiles(axes[0, col], {s.label: getattr(res, n).v[i] for n, s in cmp.series.items()},
                  interface=res.interface, v_ref=res.incident.velocity,
                  title=f"{name}, t = {cmp.times[i] * 1e3:.3f} ms")
    bx = axes[1, col]
    for n, style in (("discrete", "ko"), ("continuum", "C1^")):
        s = cmp.series[n]
        bx.plot(s.times[:i + 1] * 1e3, s.fronts[ct.front][:i + 1], style, ms=3, mfc="none",
                label=s.label)
    tt, xt = theory_trajectory(cmp, window)
    bx.plot(tt * 1e3, xt, "C3-", lw=1.2, label="theory")
    if res.interface is not None:
        bx.axhline(res.interface - 0.5, color="0.4", ls=":", lw=1.0)
    bx.set(xlabel="t (ms)", ylabel="peak position (grain index $i$)")
    bx.legend(fontsize="xx-small")
    disc, th, rel = cmp.differences["theory"][ct.quantity]
    print(f"{name}: {ct.quantity.replace('_', ' ')} {disc * 1e3:.4f} ms (discrete), "
          f"{th * 1e3:.4f} ms (theory, {rel:+.1%}); {ct.label}")
    print("   ", cmp.verdict())
fig.tight_layout()

# %%
# The forward taper's wave speeds up (its trajectory steepens) and its grain velocity
# grows as the grains get lighter; the backward one slows down.  The
# adiabatic taper wave and the homogenised cell time the leading peak to 1–2 %.  The
# continuum, built from the same per-grain masses and contact constants, follows the
# leading wave; in the dimer and trimer it homogenises what the grains resolve, so its
# profile differs in the tail the cells radiate.
#
# Growth along a slow taper: the binary-collision approximation
# --------------------------------------------------------------
# In the binary-collision approximation (BCA; Harbola, Rosas, Esposito & Lindenberg,
# Phys. Rev. E 80 (2009) 031303) each grain, struck by its predecessor, takes the
# velocity of an isolated elastic collision, v_k = 2 m_{k−1} v_{k−1}/(m_{k−1} + m_k):
# a growth of 2/(1 + q) per grain.  The adiabatic solitary wave carries a fixed energy
# C_E m v_max², so v_max ∝ m^{−1/2}: a growth of q^{−1/2} per grain.  For a slow taper
# (q = 0.98, the shipped ``chain_tapered_bca``: 30 uniform grains of 15 mm, then 40
# tapered ones) the two agree to 1e-4 per grain, and the chain follows both once the
# wave has adapted to the taper.
cmp = compare("chain_tapered_bca", progress=False)
res = cmp.run
q = cmp.scenario.chain.sections[1].mass_ratio
first = res.interface                          # the first tapered grain
vmax = res.simulation.record.vmax
grain = np.arange(first - 10, res.chain.n - 1)
fit = slice(first + 10, res.chain.n - 3)       # adapted, before the wall
growth = np.exp(np.polyfit(np.arange(res.chain.n)[fit], np.log(vmax[fit]), 1)[0])
fig, ax = plt.subplots(figsize=(7, 3.4))
ax.semilogy(grain, vmax[grain], "k.", ms=4, label="discrete: running max")
anchor = first + 10
for per_grain, style, label in ((2 / (1 + q), "C0-", "BCA, 2/(1+q) per grain"),
                                (q ** -0.5, "C3--", "adiabatic wave, $q^{-1/2}$ per grain")):
    xs = np.arange(first, res.chain.n - 1)
    ax.semilogy(xs, vmax[anchor] * per_grain ** (xs - anchor), style, lw=1.0, label=label)
ax.axvline(first - 0.5, color="0.4", ls=":", lw=1.0)
ax.set(xlabel="grain index $i$", ylabel="peak grain velocity (m/s)",
       title=f"chain_tapered_bca, q = {q:g}")
ax.legend(fontsize="x-small")
fig.tight_layout()
print(f"growth per grain: discrete {growth:.5f} (grains {fit.start}-{fit.stop - 1}), "
      f"BCA {2 / (1 + q):.5f}, adiabatic {q ** -0.5:.5f}")
print(cmp.verdict())
