"""
Dissipation: viscoelastic Hertz from a coefficient of restitution, and drag
===========================================================================

Two ways a solitary wave loses energy, on an uncompressed Hertz chain:

* **viscoelastic contacts** (Kuwabara & Kono, Jpn. J. Appl. Phys. 26 (1987) 1230;
  Brilliantov et al., Phys. Rev. E 53 (1996) 5382): F = max(0, k[δ^{3/2} +
  A δ^{1/2} δ̇]).  The damping time A is what a measurement does not give; the
  coefficient of restitution e of two grains colliding at a speed g does, and
  :meth:`theory.laws.ViscoelasticHertz.from_restitution` solves the two-body impact for
  the A that gives it (Schwager & Pöschel, Phys. Rev. E 57 (1998) 650).  To first order
  in A the wave's peak velocity decays as v_max(j) = v_0 (1 + j/j_*)^{-5} after j grains
  (:func:`theory.dissipation.kuwabara_kono_wave_decay`);
* **on-site drag** −m β v on every grain (a surrounding fluid): to first order in β
  the energy decays at the rate 2β E_kin, and v_max(j) = v_0 (1 − j/j_d)^{1/p}, p = 1/5
  (:func:`theory.dissipation.drag_wave_decay`).

Each chain is run by the three models through :func:`hertzchain.compare.compare` (the
shipped scenarios ``law_viscoelastic_hertz`` and ``law_drag``): the discrete chain, the
long-wave continuum with its viscous term (Eq. 7 with damping), and the theory's decay.
Grains are counted from 0, as everywhere in hertzchain.
"""

import matplotlib.pyplot as plt
import numpy as np

import theory
from hertzchain.compare import compare
from hertzchain.scenario import load_scenario
from theory.dissipation import drag_wave_decay, kuwabara_kono_wave_decay
from theory.laws import ViscoelasticHertz


def shipped(name, **changes):
    """A shipped scenario with some keys changed (dotted paths, as in a sweep)."""
    return load_scenario(name).with_values(changes)


# %%
# From a coefficient of restitution to the damping time
# -----------------------------------------------------
# Two of the paper's grains (reduced mass m/2) colliding at g = 1 m/s with e = 0.98
# and e = 0.90.  e of this law grows as the impact slows (it depends on g^{1/5}), so
# A holds e at that speed only.
d, mat = theory.PAPER_DIAMETER, theory.PAPER_MATERIAL
m, k = theory.grain_mass(d, mat.density), theory.hertz_constant(d, mat)
laws = {e: ViscoelasticHertz.from_restitution(e, 1.0, m / 2, k) for e in (0.98, 0.90)}
for e, law in laws.items():
    print(f"e = {e} at 1 m/s: A = {law.damping_time:.3e} s; at 0.1 m/s e = "
          f"{law.restitution(0.1, m / 2, k):.4f}")

# %%
# The damped waves, three models
# ------------------------------
# The exact lossless wave (1 m/s peak) is launched at grain 20 and decays.  Drawn:
# the discrete chain's running maximum of every grain's velocity (independent of the
# wave's phase between grains), the sampled peaks of the leading pulse of the discrete
# chain and of the continuum at their front positions, and the theory's first-order
# decay from the discrete peak at the first grain it describes.
runs = {f"viscoelastic, e = {e}": compare(
    shipped("law_viscoelastic_hertz", **{"chain.damping_time": law.damping_time}),
    progress=False) for e, law in laws.items()}
runs["drag, β = 200 /s"] = compare(shipped("law_drag"), progress=False)

fig, axes = plt.subplots(1, 3, figsize=(11, 3.4), sharey=True)
for ax, (title, cmp) in zip(axes, runs.items(), strict=True):
    res = cmp.run
    ct = res.theory.chain_theory                  # the chain's own theory (decay)
    vmax = res.simulation.record.vmax
    grain = np.arange(vmax.size)
    a = ct.first
    ahead = grain[a:int(np.nanmax(cmp.series["discrete"].fronts["incident"]))]
    if ct.kind == "drag":
        decay = drag_wave_decay(ahead - a, vmax[a], k, m, ct.params["drag"])
    else:
        decay = kuwabara_kono_wave_decay(ahead - a, vmax[a], k, m,
                                         ct.params["damping_time"])
    ax.plot(grain, vmax, "k-", lw=1.0, label="discrete: running max")
    for name, style in (("discrete", "ko"), ("continuum", "C1^")):
        s = cmp.series[name]
        ax.plot(s.fronts["incident"], s.peaks["incident"], style, ms=4, mfc="none",
                label=f"{s.label}: sampled peak")
    ax.plot(ahead, decay, "C3--", lw=1.2, label="theory, first order")
    ax.set(title=title, xlabel="grain index $i$", xlim=(0, res.chain.n))
    rel = cmp.differences["theory"][ct.quantity][2]
    print(f"{title}: peak velocity at grain {ahead[-1]}: theory {rel:+.1%} off")
    print("   ", cmp.verdict())
axes[0].set_ylabel("peak grain velocity (m/s)")
axes[0].legend(fontsize="xx-small")
fig.tight_layout()

# %%
# First order in A is good while the wave loses little per grain: e = 0.98 is within a
# few per cent, e = 0.90 (A five times as large) is 20 % off after 65 grains.  The drag is weak here
# (β = 200 /s against a collision time of ~1e-5 s) and the first-order decay is exact
# to 1e-4.  The continuum (Eq. 7 with the damping term, started from the same grains)
# decays like the chain; its sampled peaks, like the discrete ones, depend on where the
# wave sits between grains.
#
# The energy balance
# ------------------
# What the dissipative half-steps remove is booked per contact
# (:meth:`discrete.Simulation.dissipated`): E(t) + D(t) = E(0) up to the splitting
# error, second order in the time step.
for title, cmp in runs.items():
    sim = cmp.run.simulation
    e, dis, e0 = sim.energy(), sim.dissipated(), sim.energy0
    print(f"{title}: E = {e:.4e} J, D = {dis:.4e} J, (E + D - E0)/E0 = "
          f"{(e + dis - e0) / e0:+.1e}")
