r"""Energies of the chain as NumPy functions (paper Fig. 8, Table 2; docs/physics.md §6).

* kinetic energy of grain i: :math:`e^k_i = \tfrac12 m_i v_i^2` (J);
* wave potential energy of contact j: :math:`e^c_j = \tfrac25 k_j([r_j]_+^{5/2} -
  \delta_{0,j}^{5/2})` (J), the integral of Eq. 1 minus the static energy of the same
  contact (for another contact law :math:`U(r_j) - U(\delta_{0,j})` with U its elastic
  energy, :meth:`theory.laws.ContactLaw.energy`).  The linear term
  :math:`F_0 (r_j - \delta_{0,j})` is kept (docs/physics.md §6), so the potential energy
  of an expansive wave is negative;
* per grain: :math:`e^p_i = \tfrac12(e^c_i + e^c_{i+1})`, :math:`e^t_i = e^k_i + e^p_i`
  (a wall contact belongs wholly to its grain: walls store no energy);
* total :math:`E = \sum_i e^k_i + \sum_j e^c_j`, conserved by Eq. 2 with fixed walls.

The difference :math:`r^{5/2} - \delta_0^{5/2}` is evaluated as
:math:`\delta_0^{5/2}\,\mathrm{expm1}(\tfrac52\,\mathrm{log1p}((r-\delta_0)/\delta_0))`,
free of cancellation for small waves on a large precompression.
"""

from __future__ import annotations

import numpy as np

from theory import wave_contact_energy
from theory.laws import HERTZ, ContactLaw

from .reference import overlaps

__all__ = ["contact_energy", "kinetic_energy", "grain_energy", "total_energy",
           "section_energy", "coarsen"]


def contact_energy(r, k, delta0, law: ContactLaw | None = None):
    """Wave potential energy (2/5) k([r]_+^{5/2} - δ0^{5/2}) of each contact, J.

    Hertz: :func:`theory.wave_contact_energy`; another law: its
    :meth:`~theory.laws.ContactLaw.energy` (the kernels compile the law's own
    ``make_energy`` for the hot path).
    """
    if law is None or law == HERTZ or law.exponent == 1.5:
        return wave_contact_energy(r, k, delta0)
    return law.energy(r, k, delta0)


def kinetic_energy(chain, v):
    """Kinetic energy ½ m v² of each grain, J."""
    return 0.5 * chain.mass * np.asarray(v, dtype=float) ** 2


def grain_energy(chain, u, v, wall_left=0.0, wall_right=0.0, law: ContactLaw | None = None):
    """Per-grain (kinetic, potential, total) energies, J, each of shape (N,) (Fig. 8)."""
    ec = contact_energy(overlaps(u, chain.delta0, wall_left, wall_right), chain.k, chain.delta0,
                        law)
    ek = kinetic_energy(chain, v)
    ep = 0.5 * (ec[:-1] + ec[1:])
    ep[0] += 0.5 * ec[0]  # a wall contact belongs wholly to its grain
    ep[-1] += 0.5 * ec[-1]
    return ek, ep, ek + ep


def total_energy(chain, u, v, wall_left=0.0, wall_right=0.0, law: ContactLaw | None = None):
    """Total wave energy Σ ½ m v² + Σ_j (2/5) k_j([r_j]_+^{5/2} - δ0_j^{5/2}), J."""
    ec = contact_energy(overlaps(u, chain.delta0, wall_left, wall_right), chain.k, chain.delta0,
                        law)
    return float(np.sum(kinetic_energy(chain, v)) + np.sum(ec))


def section_energy(chain, per_grain):
    """Sum a per-grain quantity (..., N) over each section; returns (..., n_sections)."""
    per_grain = np.asarray(per_grain)
    return np.stack([per_grain[..., s].sum(axis=-1) for s in chain.section_slices()], axis=-1)


def coarsen(per_grain, factor: int):
    """Sum a per-grain array (..., N) over blocks of ``factor`` grains (last block partial)."""
    if int(factor) < 1:
        raise ValueError(f"factor must be an integer >= 1 (got {factor!r})")
    per_grain = np.asarray(per_grain)
    n = per_grain.shape[-1]
    starts = np.arange(0, n, int(factor))
    return np.add.reduceat(per_grain, starts, axis=-1)
