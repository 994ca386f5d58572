"""
Theory predictions for an interface
===================================

The closed-form theory (:mod:`theory`) needs no simulation: for a pair of density and
stiffness ratios it gives the sound-speed and impedance ratios (paper Eqs. 9, 13), the
transmission of force, velocity and energy (Eq. 12), the Fig. 7 region, and the
weakly nonlinear fission parameter q (docs/physics.md §8).
"""

import matplotlib.pyplot as plt
import numpy as np

import theory

# %%
# One interface: the paper's point N (γ_c0 = 1, γ_RG = 2).
print(theory.predict(*theory.PAPER_POINTS["N"]))

# %%
# Transmission against the impedance ratio γ_RG.  The energy coefficients sum to one;
# the force transmission exceeds one for γ_RG > 1 (a soft–hard interface).
g = np.logspace(-1, 1, 200)
fig, ax = plt.subplots(figsize=(6, 3.5))
ax.semilogx(g, theory.pressure_transmission(g), label="force, transmitted")
ax.semilogx(g, theory.velocity_transmission(g), label="velocity, transmitted")
ax.semilogx(g, theory.energy_transmission(g), label="energy, transmitted")
ax.semilogx(g, theory.energy_reflection(g), "--", label="energy, reflected")
ax.set(xlabel=r"$\gamma_{RG}$", ylabel="ratio to incident")
ax.legend(fontsize="small")
fig.tight_layout()

# %%
# The phase diagram of the transmitted wave: the paper's boundary γ_c0 = 1 and the
# fission criterion q = 1, which also accounts for the amplitude change at the
# interface.
ar, ak = np.meshgrid(np.logspace(-1, 1, 121), np.logspace(-1, 1, 121))
q = theory.fission_parameter(ar, ak)
fig, ax = plt.subplots(figsize=(5, 4.5))
pc = ax.pcolormesh(ar, ak, np.log(q), cmap="RdBu_r", vmin=-1.5, vmax=1.5, shading="auto")
ax.contour(ar, ak, theory.gamma_c0(ar, ak), levels=[1.0], colors="k", linestyles=":")
ax.contour(ar, ak, q, levels=[1.0], colors="k")
ax.set(xscale="log", yscale="log", xlabel=r"$\alpha_\rho$", ylabel=r"$\alpha_{kn}$",
       title=r"$\ln q$; solid $q = 1$, dotted $\gamma_{c0} = 1$")
fig.colorbar(pc, ax=ax)
fig.tight_layout()
