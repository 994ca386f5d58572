"""
Contact laws: the exponent n of F = k δⁿ (Hertz, cones, linear springs)
=======================================================================

A grain struck at 1 m/s on an uncompressed chain launches one solitary wave if the
contact law F = k[δ]₊ⁿ is stiffer than linear (n > 1: a "sonic vacuum").  Its speed
grows with its amplitude as V ∝ v_max^((n−1)/(n+1)) — v_max^(1/5) for Hertz spheres
(n = 3/2), v_max^(1/3) for cones (n = 2) — and its width does not depend on the
amplitude: the long-wave compacton spans π d/((n−1)√(6/(n(n+1)))), 4.97 grains for
Hertz and π grains for cones (Nesterenko, *Dynamics of Heterogeneous Materials*, 2001,
§1.1–1.4).  Linear springs
(n = 1) have no solitary wave: the struck grain's pulse spreads with the dispersion
relation ω = 2√(k/m)|sin(q/2)|, and the exact solution of the harmonic chain is a sum of
Bessel functions (Schrödinger, Ann. Phys. 349 (1914) 916).

Each chain is run by the three models where they apply, through
:func:`hertzchain.compare.compare` on the shipped scenarios ``law_power_cones`` and
``law_linear`` (``hertzchain compare law_power_cones`` does the same from the command
line): the discrete chain, the continuum (``"auto"`` at δ0 = 0: the grain-averaged
quasi-continuum for exponent n, docs/physics.md §24–25) and the theory (Nesterenko's
speed for exponent n; Schrödinger's front for n = 1).
Grains are counted from 0, as everywhere in hertzchain.
"""

import matplotlib.pyplot as plt
import numpy as np
from scipy.special import jv

import theory
from hertzchain.compare import compare
from hertzchain.plotting import plot_profiles
from hertzchain.scenario import load_scenario


def shipped(name, **changes):
    """A shipped scenario with some keys changed (dotted paths, as in a sweep)."""
    return load_scenario(name).with_values(changes)


# %%
# Hertz (n = 3/2) and cones (n = 2)
# ---------------------------------
# The same impact on 120 grains, with the exponent changed.  The velocity profiles
# are drawn at the comparison time (the last sample before a wave reaches a chain
# end), around the wave; the vertical line is the theory's peak position, the incident
# wave moving at Nesterenko's speed for its measured amplitude.  (The contact constant
# keeps its value, in N/m^n, so the speeds of different n are not comparable.)
runs = {n: compare(shipped("law_power_cones", **{"chain.exponent": n}), progress=False)
        for n in (1.5, 2.0)}

fig, axes = plt.subplots(1, 2, figsize=(9, 3.4), sharey=True)
for ax, (n, cmp) in zip(axes, runs.items(), strict=True):
    res, i = cmp.run, cmp.i_compare
    t = cmp.times[i]
    plot_profiles(ax, {s.label: getattr(res, name).v[i] for name, s in cmp.series.items()},
                  v_ref=res.incident.velocity, title=f"n = {n:g}, t = {t * 1e3:.3f} ms")
    ax.axvline(res.theory.fronts(t)["incident"], color="C3", lw=0.9, label="theory: peak")
    ax.legend(fontsize="x-small", loc="upper left")
    peak = int(np.argmax(res.discrete.v[i]))
    ax.set_xlim(peak - 15, peak + 8)
axes[1].set_ylabel("")
fig.tight_layout()

for n, cmp in runs.items():
    disc, th, rel = cmp.differences["theory"]["speed_incident"]
    width = theory.profiles.compacton_width(1.0, n)  # in grain diameters
    print(f"n = {n:g}: incident speed {disc:.1f} m/s (discrete), {th:.1f} m/s "
          f"(Nesterenko, {rel:+.1%}); peak velocity {cmp.run.incident.velocity:.3f} m/s; "
          f"compacton width {width:.2f} grains")
    print("   ", cmp.verdict())

# %%
# The cone wave is narrower than Hertz's, as the compacton widths say.  The continuum
# ends within a grain of the chain's wave (0.7 grain behind for Hertz, 0.3 for cones)
# and sheds small pulses behind it (the impact is a velocity jump, not a long wave): on
# a pulse a few grains wide a lag of one grain is a profile L2 difference of order one,
# which the verdict reports as such.  Its front speed, fitted over the settling impact
# wave, is within 1 % for Hertz but 10 % fast for cones (Eq. 7: 1.3 % and 1.8 %, with
# lags of 1.2 and 0.7 grains; docs/physics.md §25).
#
# Linear springs (n = 1)
# ----------------------
# The impact on a chain of linear springs whose first grain touches a fixed wall through
# a spring.  With a node at site −1 the method of images turns Schrödinger's solution of
# the infinite chain, v_i = v0 J_2i(ωt), into
#
# .. math:: v_i(t) = v_0\,[J_{2i}(\omega t) - J_{2i+4}(\omega t)], \qquad
#           \omega = 2\sqrt{k/m},
#
# exact for the harmonic chain until the front reaches the far end.  The continuum
# does not apply (no long wave forms); compare says why and leaves it off.
lin = compare(shipped("law_linear", **{"run.t_end": 2.5e-5}), progress=False)
res = lin.run
print("not run:", res.skipped)
print(lin.verdict())

d, k, m = res.discrete, float(res.chain.k[1]), float(res.chain.mass[0])
v0 = float(lin.scenario.initial.v0)
omega = 2.0 * np.sqrt(k / m)
grain = np.arange(res.chain.n)
fig, ax = plt.subplots(figsize=(8, 3.2))
for j, style in ((len(d.times) // 2, "C0"), (len(d.times) - 1, "k")):
    t = d.times[j]
    exact = v0 * (jv(2 * grain, omega * t) - jv(2 * grain + 4, omega * t))
    ax.plot(grain, d.v[j] / v0, ".", color=style, ms=4,
            label=f"discrete, t = {t * 1e6:.1f} µs")
    ax.plot(grain, exact / v0, "-", color=style, lw=0.8, alpha=0.7,
            label="$J_{2i} - J_{2i+4}$ (exact)")
    print(f"t = {t * 1e6:.1f} µs: max |v_discrete - v_exact| / v0 = "
          f"{np.max(np.abs(d.v[j] - exact)) / v0:.1e}")
ax.set(xlabel="grain index $i$", ylabel="$v_i / v_0$",
       title="linear springs: a dispersive pulse, no solitary wave")
ax.legend(fontsize="x-small", ncol=2)
fig.tight_layout()

# %%
# The difference is the velocity-Verlet time-step error (second order in the step);
# the front (the first maximum of J_2i, at ωt ≈ 2i + 0.81 (2i)^{1/3}, Abramowitz &
# Stegun 9.5.16) is what the theory of ``compare`` times against the discrete chain.
