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

__all__ = ["overlaps", "overlap_rates", "forces", "accelerations", "step", "run"]


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
