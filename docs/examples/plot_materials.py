"""
Materials: a library material against a measured one
====================================================

Two sections of grains of the same diameter but different materials meet at an
interface.  Their density ratio α_ρ and contact-stiffness ratio α_kn follow from the
materials (the Hertz constant of two identical spheres, k = E d^{1/2}/(3(1 − ν²)),
docs/physics.md §1 — half the paper's printed k_n), and with them the sound-speed
ratio γ_c0 = α_ρ^{-1/2} α_kn^{1/3} and the impedance ratio γ_RG = α_ρ^{1/2} α_kn^{1/3}
(paper Eqs. 9, 13) that decide how a weak solitary wave of a precompressed chain is
transmitted and reflected (linear acoustics, Eqs. 10–12;
:func:`theory.table2_prediction`).

A material is a name from the library (``hertzchain materials``: density, Young's
modulus, Poisson ratio, each with its source) or a table of measured values.  Here
stainless steel 316 from the library meets an aluminium alloy given by its measured
values, δ0/d = 1e-3, the exact solitary wave of the paper's amplitude (0.0822 m/s),
run by the three models through :func:`hertzchain.compare.compare`: the discrete
chain, the continuum (Eq. 4 in its regularised form, docs/physics.md §2) and the
theory.  Then three sections of their own diameters and materials (the shipped
``chain_sections``).  Grains are counted from 0, as everywhere in hertzchain.
"""

import matplotlib.pyplot as plt
import numpy as np

import theory
from hertzchain.compare import compare
from hertzchain.plotting import mark_interface, plot_energy_partition, plot_profiles
from hertzchain.scenario import parse_scenario

# %%
# The library
# -----------
for name in ("steel", "chrome_steel", "brass", "aluminium", "glass", "ptfe"):
    mat = theory.get_material(name)
    print(f"{name:13} {mat.density:7.0f} kg/m³  E = {mat.youngs_modulus / 1e9:6.1f} GPa  "
          f"ν = {mat.poisson_ratio:.2f}")

measured = {"density": 2700.0, "youngs_modulus": 70e9, "poisson_ratio": 0.33,
            "name": "aluminium alloy (measured)"}
steel = theory.get_material("steel")
alloy = theory.Material(measured["density"], measured["youngs_modulus"],
                        measured["poisson_ratio"])
alpha_rho, alpha_kn = theory.material_ratios(steel, alloy)
print(f"steel -> alloy: α_ρ = {alpha_rho:.4f}, α_kn = {alpha_kn:.4f}")
print(theory.predict(alpha_rho, alpha_kn))

# %%
# The interface, three models
# ---------------------------
n_left, n_right = 200, 200
cmp = compare(parse_scenario({
    "name": "steel-alloy",
    "chain": {"delta0_over_d": 1e-3, "material": "steel",
              "sections": [{"n": n_left}, {"n": n_right, "material": measured}]},
    "initial": {"kind": "exact_wave", "center": 100, "velocity_max": 0.0822},
    "run": {"until_front_at": n_left + 100},
}), progress=False)
res = cmp.run
print(cmp.verdict())

fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 3.6))
i = cmp.i_compare
plot_profiles(ax, {s.label: getattr(res, n).v[i] for n, s in cmp.series.items()},
              interface=res.interface, v_ref=res.incident.velocity,
              title=f"steel | alloy, t = {cmp.times[i] * 1e3:.3f} ms")
th = res.theory
plot_energy_partition(
    bx, {s.label: (s.times[:i + 1], s.energy["total_left"][:i + 1],
                   s.energy["total_right"][:i + 1]) for s in cmp.series.values()},
    theory=(cmp.times, th.partition(cmp.times)["left"], th.partition(cmp.times)["right"]),
    t_compare=cmp.t_compare)
bx.set_title("energy left and right of the interface")
bx.legend(fontsize="xx-small", loc="center right")
fig.tight_layout()

for key in ("Et_tr", "Et_re"):
    row = {name: rows[key] for name, rows in cmp.differences.items() if key in rows}
    print(key, {name: f"{model:.4f} (discrete {disc:.4f})"
                for name, (disc, model, _) in row.items()})

# %%
# The alloy is lighter and softer than steel (α_ρ ≈ 0.34, α_kn ≈ 0.37): γ_RG ≈ 0.42 < 1,
# so the reflected wave is expansive (its grains move forward, behind the interface),
# and γ_c0 ≈ 1.24 > 1 puts the point in the paper's "fracture" region; the weakly
# nonlinear fission parameter q ≈ 0.95 < 1, which also counts the amplitude change at
# the interface, predicts a single transmitted solitary wave (docs/physics.md §8), as
# the chain shows.  The energies are those of the paper's Table 2: the potential
# energy is counted from the static state, so its part linear in the overlap change,
# F0 Σ(r − δ0), carries the sign of the wave (docs/physics.md §6).  The expansive
# reflected wave therefore carries negative total energy and the transmitted one more
# than the incident energy (Et_re ≈ −0.37, Et_tr ≈ 1.37; they sum to one).  Linear
# acoustics gets them to 4e-3 at this amplitude (dynamic strain ≈ 0.1 δ0), the
# continuum to 3e-4.
#
# Any number of sections, each its own diameter and material
# ----------------------------------------------------------
# The shipped scenario ``chain_sections``: 4 mm grains, then 6 mm grains of half the
# density, then 4 mm grains twice as stiff, struck at 0.5 m/s (δ0/d = 1e-4).  The
# continuum discretises the per-grain masses and contact constants (the contact
# between two diameters has its own Hertz constant, theory.hertz_constant with
# R* = R1 R2/(R1 + R2)); the theory describes the incident wave, and says that no
# interface theory covers sections of different diameters.
cmp = compare("chain_sections", progress=False)
res = cmp.run
v = res.discrete.v                                  # (sample, grain), m/s
# the samples at which the wave's leading edge (|v| > 5 % of the incident peak) first
# reaches grains 20, 60 and 100: one per section, before any wave meets the far wall
edge = [np.flatnonzero(np.abs(row) > 0.05 * res.incident.velocity).max(initial=0)
        for row in v]
shown = [int(np.argmax(np.asarray(edge) >= g)) for g in (20, 60, 100)]
fig, axes = plt.subplots(1, len(shown), figsize=(11, 3.2), sharey=True)
for ax, i in zip(axes, shown, strict=True):
    plot_profiles(ax, {s.label: getattr(res, n).v[i] for n, s in cmp.series.items()},
                  v_ref=res.incident.velocity, title=f"t = {cmp.times[i] * 1e3:.3f} ms")
    for first in res.interfaces:
        mark_interface(ax, first)
for ax in axes[1:]:
    ax.set_ylabel("")
fig.tight_layout()
print("diameters (mm):", sorted({round(float(x) * 1e3, 3) for x in res.chain.diameter}))
print(cmp.verdict())
