r"""Energy scattering of a solitary wave at a composite-chain interface (paper Table 2).

:func:`energy_ratios` launches the paper's incident solitary wave in the left section of
a two-section chain (a :class:`theory.medium.Medium`, e.g. ``discrete.Chain.two_section(
...).medium()``, long enough by :func:`section_lengths`), lets it cross the interface
with a continuum solver, and returns the transmitted and reflected fractions of the incident
kinetic, potential and total energy, defined exactly as in the paper's Table 2 and
docs/physics.md §6: energies are computed per grain with the discrete formulas
(:mod:`continuum.sampling`), the potential energy being the contact energy minus the
static energy of the same contacts; incident energies are those of the initial wave
(entirely in the left section); transmitted/reflected energies are the right/left
section totals once the transmitted peak is ``distance`` grains past the interface.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

import theory

from .boussinesq import BoussinesqPDE
from .initial import from_grains, solitary_wave, solitary_wave_parameters
from .medium import Medium
from .nesterenko import NesterenkoPDE
from .sampling import sample_grains, section_energies
from .solver import run

__all__ = ["energy_ratios", "section_lengths", "PAPER_VELOCITY_MAX"]

PAPER_VELOCITY_MAX = 0.0822
"""Peak grain velocity of the paper's incident wave at δ0/d = 1e-3, v0 = 1 m/s, m/s
(v̄max/v0 = 0.0822, paper Section 2, Fig. 2b)."""


def section_lengths(gamma_c0: float, lead: int = 100, distance: int = 100) -> tuple[int, int]:
    """Grains (left, right) for :func:`energy_ratios` at sound-speed ratio γ_c0 = c_R/c_L.

    The left section holds the incident peak ``lead`` grains before the interface, the
    reflected wave's path while the transmitted one runs ``distance`` grains, and 100
    grains more (nothing may reach its free end: the end carries the static force F0,
    and any motion of it would add work F0 Δu to the Table-2 energies); the right one
    the transmitted wave's path and 150 grains more.
    """
    g = float(gamma_c0)
    if not (math.isfinite(g) and g > 0):
        raise ValueError(f"gamma_c0 must be > 0 (got {gamma_c0!r})")
    return (int(lead) + int(np.ceil(distance / min(g, 1.0))) + 100,
            int(np.ceil(distance * max(g, 1.0))) + 150)


def energy_ratios(
    medium: Medium,
    interface: int,
    *,
    velocity_max: float = PAPER_VELOCITY_MAX,
    lead: int = 100,
    distance: int = 100,
    n: int = 5,
    model: str = "boussinesq",
    nonlinearity: str = "quadratic",
    order: int = 4,
    safety: float = 0.5,
    initial: str | tuple[np.ndarray, np.ndarray] = "regularised",
) -> dict[str, Any]:
    """Continuum transmitted/reflected energy ratios for one interface (Table 2).

    Parameters
    ----------
    medium : Medium
        A precompressed two-section chain: grains [0, ``interface``) the left section,
        the rest the right one (e.g. ``discrete.Chain.two_section(n_left, n_right,
        alpha_rho, alpha_kn, delta0_over_d).medium()`` with the lengths of
        :func:`section_lengths`).
    interface : int
        First grain of the right section (the interface contact lies between grains
        ``interface - 1`` and ``interface``).
    velocity_max : float
        Peak grain velocity of the incident wave, m/s (paper: 0.0822 for v0 = 1 m/s).
    lead : int
        Initial distance of the incident peak from the interface, grains.
    distance : int
        The ratios are measured when the transmitted peak is this many grains past the
        interface (docs/physics.md §6: for point P Ek_tr drifts slowly with distance).
        The sections must be at least :func:`section_lengths` long for ``lead`` and
        ``distance``.
    n : int
        Nodes per grain (odd).
    model : {"boussinesq", "nesterenko"}
        Regularised Eq. 4 (:class:`BoussinesqPDE`) or Eq. 7 (:class:`NesterenkoPDE`).
    nonlinearity : {"quadratic", "full"}
        Flux of the Boussinesq model (Eq. 4's quadratic expansion or the full law).
    order : {2, 4}
        Order of the symplectic time stepper.
    safety : float
        Time step as a fraction of the stable step, ``pde.stable_dt(state, safety)``.
    initial : {"regularised", "discrete"} or (u, v)
        Incident wave: the sech² solitary wave of the regularised Eq. 4 (default), the
        exact discrete solitary wave (:func:`theory.discrete_solitary_wave`, docs/physics.md
        §7) sampled per grain and interpolated (:func:`from_grains`), or any per-grain
        arrays (u, v) over the whole chain.

    Returns
    -------
    dict
        ``Ek_tr, Ek_re, Ep_tr, Ep_re, Et_tr, Et_re`` (Table 2 columns), ``prediction``
        (:func:`theory.table2_prediction` for the same incident energies),
        ``incident`` energies (J), ``measured_past_interface`` (grains, the actual
        transmitted peak position, to half a grain), ``peak_past_interface`` (grains,
        the same to a fraction of a grain: parabola through the three largest grain
        velocities), ``energy_drift`` (relative, of the conserved
        functional), ``gamma_c0``, ``gamma_rg`` (of the medium's linear stiffnesses and
        masses) and the run parameters.
    """
    med = medium
    n_left = int(interface)
    if not 1 <= n_left < med.n_grains:
        raise ValueError(f"interface must lie in [1, {med.n_grains - 1}] (got {interface!r})")
    k_lin = med.stiffness
    c_l = np.sqrt(k_lin[1] / med.mass[0])
    c_r = np.sqrt(k_lin[-2] / med.mass[-1])
    g_c0 = float(c_r / c_l)
    g_rg = float(np.sqrt(k_lin[-2] * med.mass[-1]) / np.sqrt(k_lin[1] * med.mass[0]))
    need_l, need_r = section_lengths(g_c0, lead, distance)
    if n_left < need_l or med.n_grains - n_left < need_r:
        raise ValueError(f"the sections are too short for lead = {lead}, distance = "
                         f"{distance}: need >= ({need_l}, {need_r}) grains, got "
                         f"({n_left}, {med.n_grains - n_left}) (section_lengths)")
    if model == "boussinesq":
        pde = BoussinesqPDE(med, n, bc="free", nonlinearity=nonlinearity)
    elif model == "nesterenko":
        amp = solitary_wave_parameters(BoussinesqPDE(med, 1), 0.0,
                                       velocity_max=velocity_max)["amplitude"]
        pde = NesterenkoPDE(med, n, bc="free", delta_floor=1e-2 * amp)
    else:
        raise ValueError(f"model must be 'boussinesq' or 'nesterenko' (got {model!r})")
    center = float(n_left - lead)
    d = float(med.diameter[0])
    if isinstance(initial, str) and initial == "regularised":
        state = solitary_wave(pde if model == "boussinesq" else BoussinesqPDE(med, n),
                              center, velocity_max=velocity_max)
        state = pde.get_initial_condition(state[0].data, state[1].data)
    elif isinstance(initial, str) and initial == "discrete":
        wave = theory.discrete_solitary_wave(med.k[1], med.mass[0], d, med.delta0[1],
                                             velocity_max=velocity_max,
                                             exponent=med.law.exponent)
        smp = wave.sample(med.n_grains, center)
        state = from_grains(pde, smp.displacement, smp.velocity)
    elif isinstance(initial, str):
        raise ValueError(f"initial must be 'regularised', 'discrete' or (u, v) (got {initial!r})")
    else:
        state = from_grains(pde, *initial)
    par = solitary_wave_parameters(BoussinesqPDE(med, 1), center, velocity_max=velocity_max)
    t_end = lead / par["speed"] + distance / float(med.sound_speed()[-2])
    dt = pde.stable_dt(state, safety=safety)
    res = run(pde, state, t_end, dt=dt, order=order, interval=t_end / 4)

    inc = section_energies(sample_grains(pde, state), n_left)["left"]
    final = sample_grains(pde, res["state"])
    sec = section_energies(final, n_left)
    inc_f = _functional_sections(pde, state, n_left)["left"]
    out: dict[str, Any] = _ratios(_functional_sections(pde, res["state"], n_left), inc_f)
    out["grains"] = _ratios(sec, inc)
    lin = inc["potential_linear"]
    # linear acoustics for the same incident energies
    out["prediction"] = theory.table2_prediction(g_rg, inc["kinetic"], lin,
                                                 inc["potential"] - lin)
    out["incident"] = inc
    out["measured_past_interface"] = float(np.argmax(final.v[n_left:]) + 0.5)
    out["peak_past_interface"] = _peak(final.v, n_left) - (n_left - 0.5)
    out["energy_drift"] = res.energy_drift
    out["gamma_c0"] = g_c0
    out["gamma_rg"] = g_rg
    out["parameters"] = {"n_left": n_left, "n_right": med.n_grains - n_left,
                         "velocity_max_m_s": velocity_max, "lead": lead,
                         "distance": distance, "n": n,
                         "model": model, "nonlinearity": nonlinearity, "order": order,
                         "safety": safety, "dt_s": dt,
                         "initial": initial if isinstance(initial, str) else "arrays"}
    return out


def _peak(v: np.ndarray, start: int) -> float:
    """Grain position of the largest v[start:], by a parabola through three grains."""
    i = start + int(np.argmax(v[start:]))
    if i <= 0 or i >= v.size - 1:
        return float(i)
    a, b, c = v[i - 1], v[i], v[i + 1]
    den = a - 2 * b + c
    return float(i + (0.5 * (a - c) / den if den != 0 else 0.0))


def _ratios(sec: dict, inc: dict) -> dict[str, float]:
    out = {}
    for kind, key in (("k", "kinetic"), ("p", "potential"), ("t", "total")):
        out[f"E{kind}_tr"] = sec["right"][key] / inc[key]
        out[f"E{kind}_re"] = sec["left"][key] / inc[key]
    return out


def _functional_sections(pde, state, n_left: int) -> dict[str, dict[str, float]]:
    """Section energies from the equation's own conserved densities, J.

    Kinetic: the functional's kinetic energy (for the Rosenau form it includes
    (m/24) u_Xt²); potential: the dynamic density W plus F0 s (so that it is the
    contact energy minus the static energy, as in Table 2).  Faces at the interface
    contact are split half to each side.
    """
    ek, ep = pde.energy_density(state)
    disc = pde.disc
    ep = ep + disc.h * pde.face_weight * disc.f0 * pde.strain(np.asarray(state[0].data))
    x_i = n_left - 0.5
    wf = np.where(np.isclose(disc.x_faces, x_i), 0.5, (disc.x_faces < x_i).astype(float))
    wn = (disc.x_nodes < x_i).astype(float)
    out = {}
    for side, a, b in (("left", wn, wf), ("right", 1 - wn, 1 - wf)):
        k, p = float(np.sum(a * ek)), float(np.sum(b * ep))
        out[side] = {"kinetic": k, "potential": p, "total": k + p}
    return out
