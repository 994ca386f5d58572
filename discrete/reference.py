r"""Plain-NumPy velocity-Verlet step for the Hertz chain — a reference for the tests only.

Same equations as :mod:`discrete.kernels` (paper Eqs. 1, 2; velocity Verlet, Swope et
al. 1982 Eq. 7), vectorised over the whole chain with the *absolute* contact forces
F_j = k_j [r_j]_+^{3/2}; no active window, no recording.  Independent of numba.
"""

from __future__ import annotations

import numpy as np

__all__ = ["overlaps", "forces", "accelerations", "step", "run"]


def overlaps(u, delta0, wall_left=0.0, wall_right=0.0):
    """Contact overlaps r_j = δ0_j + u_{j-1} - u_j with the walls as u_{-1}, u_N, m (Eq. 1)."""
    ext = np.concatenate(([wall_left], u, [wall_right]))
    return delta0 + (ext[:-1] - ext[1:])


def forces(u, k, delta0, wall_left=0.0, wall_right=0.0):
    """Contact forces k_j [r_j]_+^{3/2}, N (paper Eq. 1)."""
    r = np.maximum(overlaps(u, delta0, wall_left, wall_right), 0.0)
    return k * r**1.5


def accelerations(u, mass, k, delta0, wall_left=0.0, wall_right=0.0):
    """Accelerations (F_i - F_{i+1})/m_i, m/s² (paper Eq. 2)."""
    f = forces(u, k, delta0, wall_left, wall_right)
    return (f[:-1] - f[1:]) / mass


def step(u, v, a, dt, mass, k, delta0, wall_left=0.0, wall_right=0.0):
    """One velocity-Verlet step; returns new (u, v, a)."""
    vh = v + 0.5 * dt * a
    u = u + dt * vh
    a = accelerations(u, mass, k, delta0, wall_left, wall_right)
    return u, vh + 0.5 * dt * a, a


def run(chain, u, v, dt, nsteps, wall_left=0.0, wall_right=0.0):
    """Integrate ``nsteps`` steps of ``dt`` (s) from (u, v); returns (u, v)."""
    args = (chain.mass, chain.k, chain.delta0, wall_left, wall_right)
    u = np.array(u, dtype=float)
    v = np.array(v, dtype=float)
    a = accelerations(u, *args)
    for _ in range(int(nsteps)):
        u, v, a = step(u, v, a, dt, *args)
    return u, v
