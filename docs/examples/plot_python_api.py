"""
The Python API in twenty lines
==============================

An exact solitary wave crosses the interface of the paper's Table 2 point M
(γ_c0 = 1, γ_RG = 0.5: a "hard–soft" interface) in a precompressed chain: the
discrete solver runs it, its diagnostics give the Table 2 energy ratios, and the
linear-acoustic theory predicts them.
"""

import matplotlib.pyplot as plt

import discrete
import theory
from discrete import diagnostics as D

alpha_rho, alpha_kn = theory.PAPER_POINTS["M"]                 # density and k_n ratios
chain = discrete.Chain.two_section(250, 300, alpha_rho, alpha_kn, delta0_over_d=1e-3)
wave = discrete.exact_wave(chain, 120, velocity_max=0.0822)     # exact lattice wave (§7)
sim = wave.simulation(record=discrete.Recording(snapshots=[0.0]))  # snapshot at t = 0
info = sim.run(until=discrete.WaveAt(250 + 150))   # stop (and snapshot) at grain 400
incident, final = sim.record.snapshots[0], sim.record.snapshots[-1]
ratios = D.table2_ratios(chain, incident, final)
prediction = ratios.theory(theory.gamma_rg(alpha_rho, alpha_kn))
print(info)
for key, value in ratios.as_dict().items():
    print(f"{key}: simulated {value:+.5f}, linear theory {prediction[key]:+.5f}")

fig, ax = plt.subplots(figsize=(7, 3))
ax.plot(sim.v, lw=1)
ax.axvline(249.5, color="0.5", ls=":", label="interface")
ax.set(xlabel="grain index $i$", ylabel="v (m/s)", title=f"point M at t = {sim.t * 1e3:.3f} ms")
ax.legend()
fig.tight_layout()
