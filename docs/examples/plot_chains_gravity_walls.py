"""
A vertical chain under gravity, and walls of a material
=======================================================

**Gravity.**  A column of grains standing on a wall (grain 0 on top) is compressed by
its own weight: the contact below grain j carries F_j = F_top + g Σ_{i≤j} m_i, so the
static overlaps (F_j/k)^{2/3} grow with depth (Sinkovits & Sen, Phys. Rev. Lett. 74
(1995) 2686).  A wave launched downwards from the top meets an ever stronger
precompression and speeds up; while it is strong compared with the local static load
it is, grain by grain, the solitary wave of the local precompression carrying its
energy (Hong, Ji & Kim, Phys. Rev. Lett. 82 (1999) 3058;
:func:`theory.gravity.solitary_wave_descent`).  The shipped scenario ``chain_gravity``,
run by the three models through :func:`hertzchain.compare.compare`: the discrete
chain, the continuum (Eq. 7 on the chain's own static overlaps) and that theory.

**Walls of a material.**  A wall is a flat of some material: its Hertz constant is
k = (4/3) E* √(d/2), E* from the grain's and the wall's moduli
(:func:`theory.hertz_constant_wall`).  A solitary wave reflecting from it pushes it
with an impulse ∫(F − F0) dt equal to twice the wave's momentum (Newton; the reflected
wave is the mirror image of the incident one), whatever the wall; its peak force
depends on the wall's stiffness.  The shipped scenario ``measure_wall_force`` with
``right_wall`` set to a rigid flat, steel, brass and the paper's grain–grain constant.
Grains are counted from 0, as everywhere in hertzchain.
"""

import matplotlib.pyplot as plt
import numpy as np

from hertzchain.compare import compare
from hertzchain.plotting import plot_forces
from hertzchain.scenario import load_scenario


def shipped(name, **changes):
    """A shipped scenario with some keys changed (dotted paths, as in a sweep)."""
    return load_scenario(name).with_values(changes)


# %%
# The column
# ----------
cmp = compare("chain_gravity", progress=False)
res = cmp.run
chain, sim, ct = res.chain, res.simulation, res.theory.chain_theory
g = cmp.scenario.chain.gravity
force = g * np.cumsum(chain.mass)[:-1]               # weight above contact j = 1 … N-1, N
overlap = (force / chain.k[1:-1]) ** (2.0 / 3.0)     # Hertz: F = k δ^{3/2}
print(f"static overlaps against force equilibrium: largest relative difference "
      f"{np.max(np.abs(chain.delta0[1:-1] / overlap - 1)):.1e}")
print(cmp.verdict())

# the leading peak's trajectory: the theory from the first sample in its grains
x = cmp.series["discrete"].fronts["incident"]
ends = cmp.times < res.discrete.summary.get("t_end_reached", np.inf)
window = np.flatnonzero(np.isfinite(x) & ends & (x >= ct.first) & (x <= ct.last - 3))
a = x[window[0]]
xs = np.linspace(a, x[window[-1]], 50)
t_theory = cmp.times[window[0]] + np.array([ct.travel_time(a, b) for b in xs])

rec = sim.record.arrays()
fig, (ax, bx, cx) = plt.subplots(1, 3, figsize=(12, 3.6))
contact = np.arange(1, chain.n)
ax.plot(contact, chain.delta0[1:-1] * 1e9, "k.", ms=3, label="chain (discrete.Chain)")
ax.plot(contact, overlap * 1e9, "C3-", lw=0.9, label=r"$(g\sum m_i / k)^{2/3}$")
ax.set(xlabel="contact $j$ (below grain $j-1$)", ylabel=r"static overlap $\delta_{0,j}$ (nm)",
       title="precompression by the weight")
ax.legend(fontsize="x-small")
plot_forces(bx, rec["series_t"], rec["sensor_force"],
            [f"sensor, grain {i}" for i in rec["sensor_grains"]])
bx.set_title("embedded sensors: the wave speeds up")
upto = slice(0, window[-1] + 1)          # before the wave reaches the bottom wall
for name, style in (("discrete", "ko"), ("continuum", "C1^")):
    s = cmp.series[name]
    cx.plot(s.times[upto] * 1e3, s.fronts["incident"][upto], style, ms=3, mfc="none",
            label=s.label)
cx.plot(t_theory * 1e3, xs, "C3-", lw=1.2, label="theory (adiabatic descent)")
cx.set(xlabel="t (ms)", ylabel="peak position (grain index $i$)", title="leading peak")
cx.legend(fontsize="xx-small")
fig.tight_layout()

disc, th, rel = cmp.differences["theory"]["travel_time"]
print(f"travel time of the peak: {disc * 1e3:.4f} ms (discrete), {th * 1e3:.4f} ms "
      f"(theory, {rel:+.1%})")

# %%
# Walls of a material
# -------------------
# The same exact solitary wave (δ0/d = 1e-4, peak 0.02 m/s) reflects from four right
# walls.  Drawn: the wall force minus its static value F0.
fig, ax = plt.subplots(figsize=(7, 3.4))
for wall in ("hertz", "steel", "brass", "paper"):
    cmp = compare(shipped("measure_wall_force", **{"chain.right_wall": wall}),
                  progress=False)
    res = cmp.run
    rec = res.simulation.record.arrays()
    t, f = rec["series_t"], rec["wall_force"][:, 1]
    momentum = float(np.sum(res.chain.mass * res.initial.v))       # of the incident wave
    impulse = np.trapezoid(f - f[0], t)
    label = {"hertz": "rigid flat", "paper": "grain–grain constant"}.get(wall, wall)
    ax.plot(t * 1e3, f - f[0], lw=1.0, label=f"{label}: k = {res.chain.k[-1]:.3g} N/m$^{{3/2}}$")
    print(f"right wall {wall!r}: k = {res.chain.k[-1]:.4g} N/m^1.5, peak F - F0 = "
          f"{np.max(f - f[0]):.4f} N, impulse / (2 x momentum) = {impulse / (2 * momentum):.6f}")
ax.set(xlim=(0.85, 1.08), xlabel="t (ms)", ylabel="$F_{wall} - F_0$ (N)",
       title="reflection from a wall: same impulse, stiffer wall, higher peak")
ax.legend(fontsize="x-small")
fig.tight_layout()

# %%
# The incident wave in this scenario is also compared by the three models before it
# reaches the wall (the continuum's wall is rigid, so it is compared only until then):
print(cmp.verdict())
