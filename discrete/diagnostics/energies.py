r"""Energies of a Hertz chain per grain, per contact and per section; Table 2 ratios.

Conventions (the discrete solver's data contract): N grains, N + 1 contacts; contact j
lies between grain j-1 and grain j, contact 0 is the left wall and contact N the right
wall (Hertz constant k_j = 0 for a free end).  Overlaps r_j = δ0_j + u_{j-1} - u_j with
u_{-1} = ``wall_left`` and u_N = ``wall_right`` (m); u are displacements from static
equilibrium.

Energies (J), docs/physics.md §6 and paper Section 4 (Fig. 8, Table 2):

* kinetic, per grain: e_k,i = ½ m_i v_i²;
* potential, per contact: e_p,j = (2/5) k_j [r_j]_+^{5/2} - (2/5) k_j δ0_j^{5/2}, i.e. the
  Hertz contact energy (integral of paper Eq. 1) minus the static precompression energy
  of the same contact — negative for a contact less compressed than at rest;
* its linear part e_L,j = F0_j (r_j - δ0_j) with F0_j = k_j δ0_j^{3/2} (the first term of
  the Taylor expansion about δ0; it dominates under precompression, docs/physics.md §6) and
  the remainder e_Q,j = e_p,j - e_L,j (≥ 0, quadratic to leading order), the split that
  :func:`theory.table2_prediction` needs;
* per grain: e_i = e_k,i + ½ e_p,i + ½ e_p,i+1 (half of each adjacent grain–grain
  contact; a wall contact belongs wholly to its grain, since walls store no energy — the
  convention of :func:`discrete.energy.grain_energy`, so per-grain energies sum to the
  chain total).

All functions accept arrays with leading dimensions (e.g. a (n_times, N) space-time grid
of displacements): the grain/contact axis is the last one.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from theory import wave_contact_energy

__all__ = [
    "overlaps_from_displacements",
    "kinetic_energy",
    "contact_energy",
    "contact_linear_energy",
    "ChainEnergies",
    "chain_energies",
    "chain_energies_of",
    "snapshot_energies",
    "section_weights",
    "section_sums",
]

FloatArray = NDArray[np.float64]
Attribution = Literal["half", "left", "right"]


def _f(x: ArrayLike, name: str) -> FloatArray:
    a = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} contains NaN or inf")
    return a


def overlaps_from_displacements(
    u: ArrayLike, delta0: ArrayLike, wall_left: ArrayLike = 0.0, wall_right: ArrayLike = 0.0
) -> FloatArray:
    """Contact overlaps r_j = δ0_j + u_{j-1} - u_j, m (paper Eq. 1).

    Parameters
    ----------
    u : array_like, shape (..., N)
        Displacements from static equilibrium, m.
    delta0 : array_like, shape (N + 1,)
        Static overlaps, m.
    wall_left, wall_right : float or array_like of shape (...)
        Wall displacements u_{-1} and u_N, m (may vary along leading dimensions).

    Returns
    -------
    ndarray, shape (..., N + 1)
    """
    u = _f(u, "u")
    lead = u.shape[:-1]
    wl = np.broadcast_to(_f(wall_left, "wall_left"), lead)[..., None]
    wr = np.broadcast_to(_f(wall_right, "wall_right"), lead)[..., None]
    ext = np.concatenate([wl, u, wr], axis=-1)
    d0 = _f(delta0, "delta0")
    if d0.shape[-1] != u.shape[-1] + 1:
        raise ValueError(f"delta0 must have N + 1 = {u.shape[-1] + 1} entries (got {d0.shape})")
    return d0 + ext[..., :-1] - ext[..., 1:]


def kinetic_energy(v: ArrayLike, mass: ArrayLike) -> FloatArray:
    """Kinetic energy per grain, ½ m v², J.

    Parameters
    ----------
    v : array_like, shape (..., N)
        Grain velocities, m/s.
    mass : array_like, shape (N,)
        Grain masses, kg.
    """
    v = _f(v, "v")
    return 0.5 * _f(mass, "mass") * v * v


def contact_energy(r: ArrayLike, k: ArrayLike, delta0: ArrayLike) -> FloatArray:
    """Wave potential energy per contact, (2/5) k ([r]_+^{5/2} - δ0^{5/2}), J.

    Integral of the Hertz force (paper Eq. 1) minus the static energy of the same contact
    (docs/physics.md §6); negative when the contact is less compressed than at rest.

    Parameters
    ----------
    r : array_like, shape (..., N + 1)
        Overlaps, m.
    k : array_like, shape (N + 1,)
        Hertz constants, N/m^{3/2} (0 for a free end).
    delta0 : array_like, shape (N + 1,)
        Static overlaps, m.
    """
    return wave_contact_energy(_f(r, "r"), _f(k, "k"), _f(delta0, "delta0"))


def contact_linear_energy(r: ArrayLike, k: ArrayLike, delta0: ArrayLike) -> FloatArray:
    """Linear part of the contact potential, F0 (r - δ0) with F0 = k δ0^{3/2}, J.

    First-order Taylor term of :func:`contact_energy` about δ0 (docs/physics.md §6).  Summed
    over a wave it is F0 times the net displacement across it.
    """
    d0 = _f(delta0, "delta0")
    return _f(k, "k") * d0**1.5 * (_f(r, "r") - d0)


@dataclass(frozen=True, eq=False)
class ChainEnergies:
    """Per-grain kinetic and per-contact potential energies of one or many chain states.

    Attributes
    ----------
    kinetic : ndarray, shape (..., N)
        ½ m v² per grain, J.
    contact : ndarray, shape (..., N + 1)
        Contact potential minus static energy per contact, J (docs/physics.md §6).
    linear : ndarray, shape (..., N + 1)
        Linear part F0 (r - δ0) of ``contact``, J.
    """

    kinetic: FloatArray
    contact: FloatArray
    linear: FloatArray

    @property
    def quadratic(self) -> FloatArray:
        """Remainder ``contact - linear`` per contact, J (the Q of Table 2's theory)."""
        return self.contact - self.linear

    @property
    def potential(self) -> FloatArray:
        """Potential energy per grain, J: half of each adjacent contact, wall contacts whole."""
        c = self.contact
        p = 0.5 * (c[..., :-1] + c[..., 1:])
        p[..., 0] += 0.5 * c[..., 0]
        p[..., -1] += 0.5 * c[..., -1]
        return p

    @property
    def total(self) -> FloatArray:
        """Total energy per grain (kinetic + :attr:`potential`), J."""
        return self.kinetic + self.potential

    def sums(self) -> dict[str, Any]:
        """Whole-chain sums (wall contacts included), J: kinetic, potential, linear, ..."""
        k = self.kinetic.sum(axis=-1)
        p = self.contact.sum(axis=-1)
        lin = self.linear.sum(axis=-1)
        return {"kinetic": k, "potential": p, "linear": lin, "quadratic": p - lin,
                "total": k + p}


def chain_energies(
    v: ArrayLike,
    mass: ArrayLike,
    k: ArrayLike,
    delta0: ArrayLike,
    *,
    u: ArrayLike | None = None,
    overlaps: ArrayLike | None = None,
    wall_left: ArrayLike = 0.0,
    wall_right: ArrayLike = 0.0,
) -> ChainEnergies:
    """Energies of chain state(s) from plain arrays (docs/physics.md §6).

    Give either ``overlaps`` (N + 1 contacts) or ``u`` (with the wall displacements).

    Parameters
    ----------
    v : array_like, shape (..., N)
        Velocities, m/s.
    mass : array_like, shape (N,)
        Masses, kg.
    k : array_like, shape (N + 1,)
        Hertz constants, N/m^{3/2}.
    delta0 : array_like, shape (N + 1,)
        Static overlaps, m.
    u : array_like, shape (..., N), optional
        Displacements from static equilibrium, m.
    overlaps : array_like, shape (..., N + 1), optional
        Contact overlaps, m.
    wall_left, wall_right : float or array_like
        Wall displacements, m (used with ``u`` only).

    Returns
    -------
    ChainEnergies
    """
    if (u is None) == (overlaps is None):
        raise ValueError("give exactly one of u (m) or overlaps (m)")
    r = (overlaps_from_displacements(u, delta0, wall_left, wall_right) if overlaps is None
         else _f(overlaps, "overlaps"))
    v = _f(v, "v")
    if r.shape[-1] != v.shape[-1] + 1:
        raise ValueError(f"need N + 1 overlaps for N velocities (got {r.shape}, {v.shape})")
    return ChainEnergies(kinetic=kinetic_energy(v, mass), contact=contact_energy(r, k, delta0),
                         linear=contact_linear_energy(r, k, delta0))


def chain_energies_of(chain: Any, v: ArrayLike, *, u: ArrayLike | None = None,
                      overlaps: ArrayLike | None = None, wall_left: ArrayLike = 0.0,
                      wall_right: ArrayLike = 0.0) -> ChainEnergies:
    """:func:`chain_energies` taking ``mass``, ``k``, ``delta0`` from a ``Chain``-like object."""
    return chain_energies(v, chain.mass, chain.k, chain.delta0, u=u, overlaps=overlaps,
                          wall_left=wall_left, wall_right=wall_right)


def snapshot_energies(chain: Any, snapshot: Any) -> ChainEnergies:
    """Energies of a recorded snapshot (attributes ``v`` and ``overlaps``) of ``chain``."""
    return chain_energies(snapshot.v, chain.mass, chain.k, chain.delta0,
                          overlaps=snapshot.overlaps)


def section_weights(section: ArrayLike, interface: Attribution = "half"
                    ) -> tuple[FloatArray, FloatArray, NDArray[np.int64]]:
    """Weight matrices that sum grain and contact quantities into sections.

    A grain belongs to its section.  A contact between two grains of the same section,
    and a wall contact, belongs wholly to that grain's section; a contact between grains
    of different sections (the interface) is given half to each (``"half"``), or wholly
    to the section of the grain on its left (``"left"``) or right (``"right"``).  Every
    weight column sums to 1, so section sums add up to the chain total.

    Parameters
    ----------
    section : array_like of int, shape (N,)
        Section index of each grain (any integers, e.g. -1 for a striker).
    interface : {"half", "left", "right"}
        Attribution of interface contacts.

    Returns
    -------
    grain_w : ndarray, shape (N, S)
    contact_w : ndarray, shape (N + 1, S)
    ids : ndarray of int, shape (S,)
        The section index of each column (sorted unique values of ``section``).
    """
    raw = np.asarray(section)
    if raw.ndim != 1 or raw.size < 1 or not np.issubdtype(raw.dtype, np.integer):
        raise ValueError("section must be a non-empty 1-D array of integers")
    if interface not in ("half", "left", "right"):
        raise ValueError(f"interface must be 'half', 'left' or 'right' (got {interface!r})")
    ids, sec = np.unique(raw, return_inverse=True)
    n, s = sec.size, ids.size
    gw = np.zeros((n, s))
    gw[np.arange(n), sec] = 1.0
    cw = np.zeros((n + 1, s))
    cw[0, sec[0]] = 1.0
    cw[n, sec[-1]] = 1.0
    j = np.arange(1, n)
    left, right = sec[:-1], sec[1:]
    same = left == right
    if interface == "half":
        np.add.at(cw, (j, left), np.where(same, 1.0, 0.5))
        np.add.at(cw, (j[~same], right[~same]), 0.5)
    elif interface == "left":
        cw[j, left] = 1.0
    else:
        cw[j, right] = 1.0
    return gw, cw, ids.astype(np.int64)


def section_sums(energies: ChainEnergies, section: ArrayLike, interface: Attribution = "half"
                 ) -> dict[str, FloatArray]:
    """Kinetic, potential, linear, quadratic and total energy of each section, J.

    Returns a dict of arrays of shape (..., S), and under ``"sections"`` the section index
    of each column (see :func:`section_weights` for the attribution of wall and interface
    contacts).
    """
    gw, cw, ids = section_weights(section, interface)
    if energies.kinetic.shape[-1] != gw.shape[0]:
        raise ValueError("section must have one entry per grain")
    k = energies.kinetic @ gw
    p = energies.contact @ cw
    lin = energies.linear @ cw
    return {"kinetic": k, "potential": p, "linear": lin, "quadratic": p - lin, "total": k + p,
            "sections": ids}
