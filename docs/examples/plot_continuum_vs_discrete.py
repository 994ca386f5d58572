"""
Continuum against discrete on a short chain
===========================================

The same exact solitary wave, sampled on the grains, is run by the discrete solver and
by the regularised long-wave equation (corrected Eq. 4, Rosenau form; docs/physics.md
§2, §4) on a two-section chain, the paper's point a (α_ρ = 0.2, α_kn = 1).
"""

import matplotlib.pyplot as plt
import numpy as np

import continuum
import discrete
import theory

n_left, n_right, centre, past, nodes = 250, 150, 175, 60, 3
ar, ak = theory.PAPER_POINTS["a"]
chain = discrete.Chain.two_section(n_left, n_right, ar, ak, delta0_over_d=1e-3)
init = discrete.exact_wave(chain, centre, velocity_max=0.0822)
sim = init.simulation(record=discrete.Recording(maxima=False))
sim.run(until=discrete.WaveAt(n_left + past), progress=False)

medium = chain.medium()  # the same chain's coefficients (theory.medium.Medium)
pde = continuum.BoussinesqPDE(medium, nodes, bc="free")
res = continuum.run(pde, continuum.from_grains(pde, init.u, init.v), sim.t, interval=sim.t)
grains = continuum.sample_grains(pde, res["state"])

err = np.max(np.abs(grains.v - sim.v)) / 0.0822
print(f"t = {sim.t * 1e3:.3f} ms; max |v_continuum - v_discrete| / v_peak = {err:.3f}")

fig, ax = plt.subplots(figsize=(7, 3))
i = np.arange(sim.v.size)
ax.plot(i, sim.v, lw=1, label="discrete")
ax.plot(i, grains.v, "--", lw=1, label=f"continuum, {nodes} nodes per grain")
ax.axvline(n_left - 0.5, color="0.5", ls=":")
ax.set(xlim=(150, n_left + n_right), xlabel="grain index $i$", ylabel="velocity (m/s)")
ax.legend(fontsize="small")
fig.tight_layout()
