r"""Plain-NumPy velocity-Verlet step for the chain — a reference for the tests only.

Same equations as :mod:`discrete.kernels` (paper Eq. 2 with a contact law of
:mod:`discrete.laws`, Hertz's Eq. 1 by default; velocity Verlet, Swope et al. 1982
Eq. 7), vectorised over the whole chain with the *absolute* contact forces
:math:`F_j = F(r_j, \dot r_j; k_j)` and the law's NumPy twin; no active window, no
recording.  Velocity-dependent forces (a dissipative law, the drag -mβv) are evaluated
at the predicted velocity :math:`v^* = v^{n+1/2} + \tfrac h2 a^n`, as the kernels do.
Independent of numba.
"""

from __future__ import annotations

import numpy as np

from .laws import ContactLaw, as_law

__all__ = ["overlaps", "overlap_rates", "forces", "accelerations", "step", "run",
           "hermite_max", "refined_maxima"]


def overlaps(u, delta0, wall_left=0.0, wall_right=0.0):
    """Contact overlaps r_j = δ0_j + u_{j-1} - u_j with the walls as u_{-1}, u_N, m (Eq. 1)."""
    ext = np.concatenate(([wall_left], u, [wall_right]))
    return delta0 + (ext[:-1] - ext[1:])


def overlap_rates(v):
    """Overlap rates ṙ_j = v_{j-1} - v_j with the walls at rest, m/s."""
    ext = np.concatenate(([0.0], v, [0.0]))
    return ext[:-1] - ext[1:]


def forces(u, k, delta0, wall_left=0.0, wall_right=0.0, *, v=None,
           law: ContactLaw | None = None):
    """Contact forces F(r_j, ṙ_j; k_j), N (Hertz k_j [r_j]_+^{3/2}, paper Eq. 1, by default).

    ``v`` (m/s) is needed for a dissipative law (zero otherwise).
    """
    law = as_law(law)
    r = overlaps(u, delta0, wall_left, wall_right)
    rd = overlap_rates(np.zeros_like(u) if v is None else v)
    return law.force(r, rd, k)


def accelerations(u, mass, k, delta0, wall_left=0.0, wall_right=0.0, *, v=None,
                  law: ContactLaw | None = None, drag: float = 0.0):
    """Accelerations (F_i - F_{i+1})/m_i - β v_i, m/s² (paper Eq. 2)."""
    f = forces(u, k, delta0, wall_left, wall_right, v=v, law=law)
    a = (f[:-1] - f[1:]) / mass
    if drag:
        a = a - drag * v
    return a


def step(u, v, a, dt, mass, k, delta0, wall_left=0.0, wall_right=0.0, *,
         law: ContactLaw | None = None, drag: float = 0.0):
    """One velocity-Verlet step (predicted velocity if forces need v); new (u, v, a)."""
    law = as_law(law)
    vh = v + 0.5 * dt * a
    u = u + dt * vh
    vs = vh + 0.5 * dt * a if (law.dissipative or drag) else None
    a = accelerations(u, mass, k, delta0, wall_left, wall_right, v=vs, law=law, drag=drag)
    return u, vh + 0.5 * dt * a, a


def run(chain, u, v, dt, nsteps, wall_left=0.0, wall_right=0.0, *,
        law: ContactLaw | None = None, drag: float = 0.0):
    """Integrate ``nsteps`` steps of ``dt`` (s) from (u, v); returns (u, v)."""
    args = (chain.mass, chain.k, chain.delta0, wall_left, wall_right)
    u = np.array(u, dtype=float)
    v = np.array(v, dtype=float)
    a = accelerations(u, *args, v=v, law=law, drag=drag)
    for _ in range(int(nsteps)):
        u, v, a = step(u, v, a, dt, *args, law=law, drag=drag)
    return u, v


def hermite_max(h, y0, y1, d0, d1):
    r"""Maximum of the cubic Hermite interpolant on [0, 1], elementwise; (s, value) arrays.

    The interpolant of y with derivative d at both ends of a step h
    (:mod:`discrete.interpolation`), :math:`p'(s) = As^2 + Bs + C` with
    :math:`A = 6(y_0 - y_1) + 3h(d_0 + d_1)`, :math:`B = 6(y_1 - y_0) - h(4d_0 + 2d_1)`,
    :math:`C = hd_0`; the candidates are both ends and the roots in (0, 1) with
    :math:`p'' = 2As + B < 0`, by the textbook formula :math:`(-B \pm \sqrt{B^2 -
    4AC})/2A`, polished by two Newton steps on p'(s) = 0 (where 4AC ≪ B² the textbook
    root loses digits; a root error δ moves the value by O(δ²)).
    """
    h, y0, y1, d0, d1 = np.broadcast_arrays(*(np.asarray(x, dtype=float)
                                              for x in (h, y0, y1, d0, d1)))
    a = 6.0 * (y0 - y1) + 3.0 * h * (d0 + d1)
    b = 6.0 * (y1 - y0) - h * (4.0 * d0 + 2.0 * d1)
    c = h * d0
    best = np.maximum(y0, y1)
    s_best = np.where(y1 > y0, 1.0, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        disc = b * b - 4.0 * a * c
        sq = np.sqrt(np.where(disc >= 0.0, disc, np.nan))
        roots = [(-b + sq) / (2.0 * a), (-b - sq) / (2.0 * a), -c / b]
        use = [a != 0.0, a != 0.0, a == 0.0]
        for r, ok in zip(roots, use, strict=True):
            for _ in range(2):  # Newton on p' = 0: the textbook root loses digits when
                r = r - (a * r * r + b * r + c) / (2.0 * a * r + b)  # 4AC << B²
            ok = ok & (r > 0.0) & (r < 1.0) & (2.0 * a * r + b < 0.0)
            r = np.where(ok, r, 0.0)
            val = ((2 * r**3 - 3 * r**2 + 1) * y0 + (r**3 - 2 * r**2 + r) * h * d0
                   + (3 * r**2 - 2 * r**3) * y1 + (r**3 - r**2) * h * d1)
            better = ok & (val > best)
            best = np.where(better, val, best)
            s_best = np.where(better, r, s_best)
    return s_best, best


def refined_maxima(chain, u, v, dt, nsteps, wall_left=0.0, wall_right=0.0, *,
                   integrator="verlet", law: ContactLaw | None = None):
    r"""Sampled and refined running maxima of v over ``nsteps`` steps, in plain NumPy.

    The reference of :class:`discrete.Simulation`'s ``record.vmax`` (the largest
    synchronous v at the steps) and ``record.vmax_refined`` / ``vmax_time`` (the
    largest value of the cubic Hermite interpolant of (v, a) between the steps,
    :mod:`discrete.interpolation`): searched on *every* step of every grain
    (:func:`hermite_max`), where the kernels search only the steps beside a grain's
    largest samples (:mod:`discrete.kernels`, "Refined maxima").  Conservative laws;
    steps of :func:`discrete.integrators.step`.

    Returns
    -------
    vmax, vmax_refined, vmax_time : (N,) arrays
        m/s, m/s and s (time from the start; 0 where the maximum is the initial v).
    """
    from .integrators import step as method_step

    args = (chain.mass, chain.k, chain.delta0, wall_left, wall_right)
    u = np.array(u, dtype=float)
    v = np.array(v, dtype=float)
    a = accelerations(u, *args, law=law)
    vmax = v.copy()
    vref = v.copy()
    tref = np.zeros_like(v)
    for n in range(int(nsteps)):
        u, v1, a1 = method_step(u, v, a, dt, *args, integrator=integrator, law=law)
        s, y = hermite_max(dt, v, v1, a, a1)
        better = y > vref
        vref = np.where(better, y, vref)
        tref = np.where(better, (n + s) * dt, tref)
        vmax = np.maximum(vmax, v1)
        v, a = v1, a1
    return vmax, vref, tref
