r"""Symplectic splitting methods of the discrete solver (from :mod:`theory.splitting`), NumPy step.

Every method is a symmetric composition of kicks (:math:`v \mathrel{+}= b_s h\,a(u)`)
and drifts (:math:`u \mathrel{+}= a_s h\,v`) of "BAB" form,

.. math::
    v \mathrel{+}= b_1 h\,a,\ u \mathrel{+}= a_1 h\,v,\ v \mathrel{+}= b_2 h\,a,\ \dots,\
    u \mathrel{+}= a_S h\,v,\ v \mathrel{+}= b_{S+1} h\,a ,

with S force evaluations per step (the last kick of a step and the first of the next
share one, "first same as last").  All are symplectic and time-reversible.

The coefficients live in one table, :mod:`theory.splitting` (shared with the
continuum); this module registers its kick-first methods, ``verlet`` (the paper's
Section 2), ``yoshida4`` and ``blanes_moan4``, and steps them in NumPy.

Which one pays is an accuracy-per-cost question (``benchmarks/fig5_full.py`` measures
it on the paper's runs); with a stated accuracy (``rtol``, ``integrator="auto"``)
:mod:`discrete.timestep` measures it for the run at hand and takes the method with the
fewest force evaluations per unit time.  The Hertz force :math:`k[r]_+^{3/2}` is only C¹ at r = 0
(a gap opening or closing), where the 4th-order methods lose their order; with
precompression and no gaps the force is smooth and they keep it.
"""

from __future__ import annotations

import numpy as np

from theory.laws import ContactLaw
from theory.splitting import SPLITTINGS, Splitting, get_splitting

from .reference import accelerations, hermite_max

__all__ = ["Integrator", "INTEGRATORS", "get_integrator", "step", "run", "refined_maxima"]


Integrator = Splitting
"""A kick-first (BAB) splitting method (:class:`theory.splitting.Splitting`)."""

INTEGRATORS: dict[str, Integrator] = {n: m for n, m in SPLITTINGS.items() if m.kick_first}
"""The registered methods by name: the kick-first ones of :data:`theory.splitting.SPLITTINGS`
(the kernels step the BAB form)."""


def get_integrator(name: str | Integrator) -> Integrator:
    """The method called ``name`` (ValueError listing the choices otherwise).

    A :class:`~theory.splitting.Splitting` passes if it is kick first (the form the
    kernels step).
    """
    m = get_splitting(name, INTEGRATORS, "integrator")
    if not m.kick_first:
        raise ValueError(f"integrator {m.name!r} is drift first; the discrete solver "
                         f"steps kick-first methods: {sorted(INTEGRATORS)}")
    return m


def step(u, v, a, dt, mass, k, delta0, wall_left=0.0, wall_right=0.0,
         integrator: str | Integrator = "verlet", *, law=None):
    """One step of ``integrator`` in plain NumPy (reference for the tests); new (u, v, a).

    ``law``: a conservative contact law (:mod:`theory.laws`; default Hertz).
    """
    m = get_integrator(integrator)
    args = (mass, k, delta0, wall_left, wall_right)
    v = v + m.kick[0] * dt * a
    for s in range(m.stages):
        u = u + m.drift[s] * dt * v
        a = accelerations(u, *args, law=law)
        v = v + m.kick[s + 1] * dt * a
    return u, v, a


def run(chain, u, v, dt, nsteps, wall_left=0.0, wall_right=0.0,
        integrator: str | Integrator = "verlet", *, law=None):
    """Integrate ``nsteps`` steps of ``dt`` (s) from (u, v) in NumPy; returns (u, v)."""
    args = (chain.mass, chain.k, chain.delta0, wall_left, wall_right)
    u = np.array(u, dtype=float)
    v = np.array(v, dtype=float)
    a = accelerations(u, *args, law=law)
    for _ in range(int(nsteps)):
        u, v, a = step(u, v, a, dt, *args, integrator=integrator, law=law)
    return u, v

def refined_maxima(chain, u, v, dt, nsteps, wall_left=0.0, wall_right=0.0, *,
                   integrator="verlet", law: ContactLaw | None = None):
    r"""Sampled and refined running maxima of v over ``nsteps`` steps, in plain NumPy.

    The reference of :class:`discrete.Simulation`'s ``record.vmax`` (the largest
    synchronous v at the steps) and ``record.vmax_refined`` / ``vmax_time`` (the
    largest value of the cubic Hermite interpolant of (v, a) between the steps,
    :mod:`discrete.interpolation`): searched on *every* step of every grain
    (:func:`hermite_max`), where the kernels search only the steps beside a grain's
    largest samples (:mod:`discrete.kernels`, "Refined maxima").  Conservative laws;
    steps of :func:`step`; the interpolant's maxima by
    :func:`discrete.reference.hermite_max`.

    Returns
    -------
    vmax, vmax_refined, vmax_time : (N,) arrays
        m/s, m/s and s (time from the start; 0 where the maximum is the initial v).
    """
    args = (chain.mass, chain.k, chain.delta0, wall_left, wall_right)
    u = np.array(u, dtype=float)
    v = np.array(v, dtype=float)
    a = accelerations(u, *args, law=law)
    vmax = v.copy()
    vref = v.copy()
    tref = np.zeros_like(v)
    for n in range(int(nsteps)):
        u, v1, a1 = step(u, v, a, dt, *args, integrator=integrator, law=law)
        s, y = hermite_max(dt, v, v1, a, a1)
        better = y > vref
        vref = np.where(better, y, vref)
        tref = np.where(better, (n + s) * dt, tref)
        vmax = np.maximum(vmax, v1)
        v, a = v1, a1
    return vmax, vref, tref
