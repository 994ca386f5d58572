r"""Plain-NumPy velocity-Verlet step for the chain — a reference for the tests only.

Same equations as :mod:`discrete.kernels` (paper Eq. 2 with a contact law of
:mod:`theory.laws`, Hertz's Eq. 1 by default; velocity Verlet, Swope et al. 1982
Eq. 7), vectorised over the whole chain with the *absolute* contact forces
:math:`F_j = F(r_j, \dot r_j; k_j)` and the law's NumPy twin; no active window, no
recording.  Velocity-dependent forces (a dissipative law, the drag -mβv) are split off
as the kernels do (:mod:`discrete.kernels`, "Dissipation"): a step is
:math:`\mathcal D^*_{h/2}\,\mathcal V_h\,\mathcal D_{h/2}`, velocity Verlet for the
elastic force between two exactly solved dissipative sub-steps at fixed positions
(:func:`dissipate`), which return the energy they removed.  Independent of numba.
"""

from __future__ import annotations

import numpy as np

from theory.laws import ContactLaw, as_law

__all__ = ["overlaps", "overlap_rates", "forces", "accelerations", "dissipate", "step",
           "run", "hermite_max"]


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


def _elastic_accelerations(u, mass, k, delta0, wall_left, wall_right, law):
    """(F_el,i - F_el,i+1)/m_i, m/s²: the elastic part, which velocity Verlet integrates."""
    f = law.elastic(overlaps(u, delta0, wall_left, wall_right), k)
    return (f[:-1] - f[1:]) / mass


def dissipate(u, v, tau, mass, k, delta0, wall_left=0.0, wall_right=0.0, *,
              law: ContactLaw | None = None, drag: float = 0.0, adjoint: bool = False):
    r"""The dissipative sub-step :math:`\mathcal D_\tau` (``adjoint``: :math:`\mathcal D^*_\tau`).

    At fixed positions u (m), over τ (s): the drag :math:`v_i e^{-\beta\tau}`, the even
    contacts, the odd contacts (D* the reverse order); per contact j between grains
    L = j-1 and R = j (walls: 1/m = 0, v = 0), with :math:`c_j` the law's damping
    coefficient (N·s/m) and :math:`s_j = 1/m_L + 1/m_R` (1/kg),

    .. math::
        P_j = \max\big(w_j(1 - e^{-c_j s_j\tau})/s_j,\ -\tau F_{el}(r_j)\big),\quad
        v_L \mathrel{-}= P_j/m_L,\ v_R \mathrel{+}= P_j/m_R,

    w = v_L - v_R.  Returns (v', ΔD) with ΔD (J) the energy removed, :math:`\sum_j P_j
    \bar w_j + \sum_i \tfrac12 m_i (v_i^2 - v_i'^2)`: exactly the kinetic energy lost.
    """
    law = as_law(law)
    ext = np.concatenate(([0.0], np.array(v, dtype=float), [0.0]))  # walls at rest
    inv = np.concatenate(([0.0], 1.0 / np.asarray(mass, float), [0.0]))
    r = overlaps(u, delta0, wall_left, wall_right)
    c = law.damping(r, k) if law.dissipative else np.zeros_like(r)
    fel = law.elastic(r, k)
    removed = 0.0

    def contacts(parity):
        nonlocal removed
        j = np.arange(parity, r.size, 2)
        j = j[c[j] > 0]
        s = inv[j] + inv[j + 1]
        w = ext[j] - ext[j + 1]
        p = np.maximum(-w * np.expm1(-c[j] * s * tau) / s, -tau * fel[j])
        vl, vr = ext[j] - p * inv[j], ext[j + 1] + p * inv[j + 1]
        removed += float(np.sum(p * (0.5 * ((ext[j] + vl) - (ext[j + 1] + vr)))))
        ext[j], ext[j + 1] = vl, vr
        ext[0] = ext[-1] = 0.0  # the walls do not move

    def grains():
        nonlocal removed
        vi = ext[1:-1]
        vn = vi * np.exp(-drag * tau)
        removed += float(np.sum(0.5 * (vi - vn) * (vi + vn) * np.asarray(mass, float)))
        ext[1:-1] = vn

    if law.dissipative:
        order = [lambda: contacts(0), lambda: contacts(1)]
    else:
        order = []
    if drag:
        order = [grains] + order
    for f in (reversed(order) if adjoint else order):
        f()
    return ext[1:-1].copy(), removed


def step(u, v, a, dt, mass, k, delta0, wall_left=0.0, wall_right=0.0, *,
         law: ContactLaw | None = None, drag: float = 0.0, dissipated: bool = False):
    r"""One step; new (u, v, a) (and the energy dissipated in it, J, if ``dissipated``).

    Velocity Verlet (Swope et al. 1982, Eq. 7); with velocity-dependent forces
    :math:`\mathcal D^*_{h/2}\,\mathcal V_h\,\mathcal D_{h/2}` (module docstring),
    a being then the elastic acceleration.
    """
    law = as_law(law)
    if not (law.dissipative or drag):
        vh = v + 0.5 * dt * a
        u = u + dt * vh
        a = accelerations(u, mass, k, delta0, wall_left, wall_right, law=law)
        out = (u, vh + 0.5 * dt * a, a)
        return out + (0.0,) if dissipated else out
    args = (mass, k, delta0, wall_left, wall_right)
    v, d1 = dissipate(u, v, 0.5 * dt, *args, law=law, drag=drag)
    vh = v + 0.5 * dt * a
    u = u + dt * vh
    a = _elastic_accelerations(u, *args, law)
    v, d2 = dissipate(u, vh + 0.5 * dt * a, 0.5 * dt, *args, law=law, drag=drag,
                      adjoint=True)
    return (u, v, a, d1 + d2) if dissipated else (u, v, a)


def run(chain, u, v, dt, nsteps, wall_left=0.0, wall_right=0.0, *,
        law: ContactLaw | None = None, drag: float = 0.0, dissipated: bool = False):
    """Integrate ``nsteps`` steps of ``dt`` (s) from (u, v); returns (u, v).

    With ``dissipated``: (u, v, D), D the energy the steps dissipated, J.
    """
    law = as_law(law)
    args = (chain.mass, chain.k, chain.delta0, wall_left, wall_right)
    u = np.array(u, dtype=float)
    v = np.array(v, dtype=float)
    if law.dissipative or drag:
        a = _elastic_accelerations(u, *args, law)
    else:
        a = accelerations(u, *args, law=law)
    total = 0.0
    for _ in range(int(nsteps)):
        u, v, a, d = step(u, v, a, dt, *args, law=law, drag=drag, dissipated=True)
        total += d
    return (u, v, total) if dissipated else (u, v)


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
