r"""Homogenised long waves of periodic chains (dimers, trimers, …).

A section whose grains repeat a unit cell of P grains (masses m_1 … m_P, contacts of
constants k_1 … k_P with the same exponent n) carries long waves — wider than the cell
— that see the cell only through three numbers (Porter, Daraio, Herbold, Szelengowicz &
Kevrekidis, Phys. Rev. E 77 (2008) 015601 and Physica D 238 (2009) 666: the long-wave
equation of heterogeneous periodic chains, its solitary wave's width and speed):

* the mean mass per grain :math:`\bar m = \tfrac1P\sum m_i`;
* the effective contact: at leading order every contact of a cell carries the same
  force F (the cell accelerates as a whole), so the mean overlap per grain is
  :math:`\bar\delta = \tfrac1P\sum (F/k_j)^{1/n} = (F/k_{eff})^{1/n}` with
  :math:`k_{eff}^{-1/n} = \tfrac1P\sum k_j^{-1/n}`: a power law again, with the mean
  static overlap :math:`\bar\delta_0`;
* the dispersion length: linearised, the acoustic branch of the cell's lattice is
  :math:`\omega^2 = \frac{\kappa^2}{\bar m\bar C}\,(1 - \ell^2\kappa^2 + O(\kappa^4))`
  (κ per grain, C_j = ∂δ_j/∂F the contacts' compliances), and the cell's ℓ² replaces
  the monoatomic 1/12.  From the transfer matrix of one cell,
  :math:`\mathrm{tr}\,T(\omega^2) = 2 - a_1\omega^2 + a_2\omega^4 - \dots
  = 2\cos P\kappa`, :math:`a_1 = P^2\bar m\bar C` and

  .. math:: \ell^2 = \frac{P^2}{12} - \frac{a_2}{P^2\,\bar m^2\bar C^2};

  for a dimer of equal contacts :math:`\ell^2 = \frac{m_1^2 - m_1m_2 + m_2^2}
  {3(m_1 + m_2)^2}` (1/12 at m1 = m2).  For equal exponents the compliance ratios
  C_j/C̄ = k_j^{-1/n}/mean(k^{-1/n}) do not depend on the force, so ℓ² is one number
  for every amplitude, the sonic vacuum included.

The homogenised section is then the monoatomic long-wave equation with m̄, k_eff, δ̄0
and its dispersive term scaled by the *dispersion ratio* 12ℓ² (:func:`homogenise`;
the Rosenau form's mass operator m̄(1 - ℓ²∂²), the strongly nonlinear form's
n/(6(n+1)) × 12ℓ²; docs/physics.md, "Long waves on any chain").  Sampled per grain,
the homogenised force F at a contact gives that contact's own overlap (F/k_j)^{1/n}
(:func:`continuum.sample_grains`).
"""

from __future__ import annotations

import numpy as np
from numpy.polynomial import Polynomial

from theory.laws import ContactLaw
from theory.medium import Medium

__all__ = ["homogenise", "cell_dispersion", "cell_stiffness", "power_elastic"]


def power_elastic(law: ContactLaw) -> bool:
    """Whether the law's elastic part is the power law k[δ]_+^n of the base class."""
    return all(getattr(type(law), m) is getattr(ContactLaw, m)
               for m in ("elastic", "make_elastic"))


def cell_stiffness(k, exponent: float) -> float:
    """Effective constant k_eff of contacts k_j in series, mean(k^{-1/n})^{-n}, N/m^n."""
    k = np.asarray(k, float)
    return float(np.mean(k ** (-1.0 / exponent)) ** (-exponent))


def cell_dispersion(mass, compliance) -> float:
    r"""Dispersion length² ℓ² (grains²) of the acoustic branch of a periodic cell.

    ``mass`` (P grain masses) and ``compliance`` (P contact compliances, the contact
    left of each grain; any common unit: only ratios matter).  From the transfer matrix
    T(λ = ω²) of one cell (module docstring): tr T = 2 - a_1 λ + a_2 λ² - …, and
    ℓ² = P²/12 - a_2/(P² m̄² C̄²); 1/12 for one grain.
    """
    m = np.asarray(mass, float)
    c = np.asarray(compliance, float)
    if m.shape != c.shape or m.ndim != 1 or m.size < 1:
        raise ValueError("mass and compliance need one entry per grain of the cell")
    if not (np.all(m > 0) and np.all(c > 0)):
        raise ValueError("mass and compliance must be > 0")
    p = m.size
    m, c = m / m.mean(), c / c.mean()
    one, zero = Polynomial([1.0]), Polynomial([0.0])
    t = [[one, zero], [zero, one]]
    for mj, cj in zip(m, c, strict=True):
        # contact j: (u_{j-1}, f_j) -> (u_{j-1} - C_j f_j, f_j); grain j: f_{j+1} = f_j + λ m_j u_j
        contact = [[one, Polynomial([-cj])], [zero, one]]
        grain = [[one, zero], [Polynomial([0.0, mj]), one]]
        step = [[sum((grain[a][b] * contact[b][e] for b in range(2)), zero)
                 for e in range(2)] for a in range(2)]
        t = [[sum((step[a][b] * t[b][e] for b in range(2)), zero) for e in range(2)]
             for a in range(2)]
    tr = (t[0][0] + t[1][1]).coef
    tr = np.r_[tr, np.zeros(3)]
    a1, a2 = -tr[1], tr[2]
    if not np.isclose(a1, p * p, rtol=1e-12):  # pragma: no cover - an algebra slip
        raise AssertionError(f"transfer matrix: a1 = {a1}, expected P² = {p * p}")
    return float(p * p / 12.0 - a2 / (p * p))


def homogenise(medium: Medium) -> tuple[Medium, np.ndarray | None]:
    """The long-wave medium of ``medium``: its periodic sections homogenised.

    Returns ``(effective, dispersion)``: ``medium`` itself and None if it has no
    periodic sections (``medium.cells``); otherwise a medium whose grains of each
    periodic section carry the cell's mean mass and whose contacts inside it (between
    its first and last grain) carry k_eff and the overlap balancing the same static
    force (module docstring), with ``dispersion`` the per-contact ratio 12ℓ²/1 (1
    outside the cells).  The cell is read from the first full cell of the section
    (grains start … start+P-1, contacts start+1 … start+P); the section needs at least
    P + 1 grains.  ValueError for a law whose elastic part is not a power law.
    """
    if not medium.cells:
        return medium, None
    law = medium.law
    if not power_elastic(law):
        raise ValueError(f"homogenised periodic sections need a power-law elastic part "
                         f"(got {law.describe()})")
    n = law.exponent
    mass = medium.mass.copy()
    k = medium.k.copy()
    disp = np.ones(medium.n_grains + 1)
    for start, stop, p in medium.cells:
        if p == 1:
            continue
        if stop - start < p + 1:
            raise ValueError(f"periodic section [{start}, {stop}) is shorter than one cell "
                             f"of {p} grains plus one")
        m_cell = medium.mass[start:start + p]
        k_cell = medium.k[start + 1:start + p + 1]
        mass[start:stop] = m_cell.mean()
        k[start + 1:stop] = cell_stiffness(k_cell, n)
        disp[start + 1:stop] = 12.0 * cell_dispersion(m_cell, k_cell ** (-1.0 / n))
    # static overlaps balancing the static forces with the effective masses and constants
    present = medium.k > 0
    f0 = medium.f0
    f_top = float(np.median((f0 - medium.gravity * np.r_[0.0, np.cumsum(medium.mass)])[present]))
    force = f_top + medium.gravity * np.r_[0.0, np.cumsum(mass)]
    d0 = np.zeros_like(k)
    d0[present] = law.static_overlap(np.maximum(force[present], 0.0), k[present])
    if not medium.gravity:
        same = present & (k == medium.k)
        d0[same] = medium.delta0[same]
    if medium.sonic_vacuum:
        d0[:] = 0.0
    eff = Medium(mass, k, d0, medium.diameter, law=law, drag=medium.drag,
                 gravity=medium.gravity, cells=(), info={**medium.info, "homogenised": True})
    return eff, disp
