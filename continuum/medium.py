r"""The chain as a continuous medium: piecewise mass, stiffness and precompression.

Coordinates
-----------
Lengths along the chain are measured in grain diameters, ``X = x/d``, so grain ``i``
sits at ``X = i`` and contact ``j`` (between grains ``j-1`` and ``j``; contact 0 and
contact N touch the walls) at ``X = j - 1/2``.  Displacements ``u`` stay in metres and
time in seconds, so continuum fields line up with the discrete solver's ``u_i(t)``,
``v_i(t)`` grain by grain.

Discretisation (staggered, conservative)
----------------------------------------
``n`` nodes per grain (``n`` odd) at ``X_p = -1/2 + (p + 1/2)/n`` carry ``u`` and
``v``; faces at ``X_q = -1/2 + q/n`` carry the strain and the contact force.  Because
``n`` is odd a node sits exactly on every grain centre and every contact is a face,
so

* the mass of node ``p`` is the mass of the grain whose cell ``[i-1/2, i+1/2]``
  contains it, and
* the stiffness of face ``q`` is that of the contact whose *dual cell* ``(j-1, j)``
  (from grain centre to grain centre) contains the face.

This reproduces the chain's total mass ``Σ m_i`` and total compliance ``Σ 1/K_j``
exactly, for any ``n``; a material interface is a jump of the mass at a contact face
and of the stiffness at the grain centres either side of the interface contact, whose
own (harmonic-mean) stiffness fills the dual cell between them.  The static overlap of
every face follows from force equilibrium ``k δ0^{3/2} = F0`` (paper, below Eq. 9).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from theory import PAPER_DIAMETER, PAPER_MATERIAL, Material, grain_mass, hertz_constant
from theory import static_overlaps as _static_overlaps

__all__ = ["Medium", "Discretisation", "BOUNDARY_CONDITIONS"]

BOUNDARY_CONDITIONS = ("free", "wall", "periodic")
"""Supported boundary conditions of the continuum solvers.

``"free"``: the end carries the static force F0 but no dynamic force (a constant-load
piston; the natural boundary condition, zero dynamic flux).  ``"wall"``: a rigid wall at
``X = -1/2`` (``N - 1/2``) with ``u = 0``.  ``"periodic"``: the chain closes on itself
(contact 0 = contact N; ``u`` must then be periodic)."""


@dataclass(frozen=True)
class Discretisation:
    """Node and face coefficients of a :class:`Medium` on ``n`` nodes per grain.

    Attributes
    ----------
    n : int
        Nodes per grain (odd).
    h : float
        Node spacing, grain diameters (= 1/n).
    x_nodes : numpy.ndarray
        Node positions, grain diameters.
    x_faces : numpy.ndarray
        Face positions, grain diameters (``N n + 1`` faces; ``N n`` if periodic).
    mass : numpy.ndarray
        Grain mass assigned to each node, kg.
    k : numpy.ndarray
        Hertz constant of each face, N/m^{3/2}.
    delta0 : numpy.ndarray
        Static overlap of each face, m.
    grain_nodes : numpy.ndarray
        Index of the node at each grain centre.
    contact_faces : numpy.ndarray
        Index of the face at each contact.
    periodic : bool
        Whether the domain is periodic.
    """

    n: int
    h: float
    x_nodes: np.ndarray
    x_faces: np.ndarray
    mass: np.ndarray
    k: np.ndarray
    delta0: np.ndarray
    grain_nodes: np.ndarray
    contact_faces: np.ndarray
    periodic: bool

    @property
    def force0(self) -> float:
        """Static contact force F0 = k δ0^{3/2} (paper Eq. 1), N."""
        return float(self.k[0] * self.delta0[0] ** 1.5)

    @property
    def stiffness(self) -> np.ndarray:
        """Linearised face stiffness K = (3/2) k δ0^{1/2} (derivative of Eq. 1), N/m."""
        return 1.5 * self.k * np.sqrt(self.delta0)

    @property
    def face_mass(self) -> np.ndarray:
        """Mass on each face, the mean of the two adjacent nodes (walls: the one node), kg."""
        m = self.mass
        if self.periodic:
            return 0.5 * (m + np.roll(m, 1))
        out = np.empty(m.size + 1)
        out[1:-1] = 0.5 * (m[1:] + m[:-1])
        out[0], out[-1] = m[0], m[-1]
        return out


@dataclass(frozen=True)
class Medium:
    """A one-dimensional chain of grains as plain arrays (no discrete-solver objects).

    Parameters
    ----------
    mass : array, shape (N,)
        Grain masses, kg.
    k : array, shape (N+1,)
        Hertz constants of the contacts, N/m^{3/2}; contact ``j`` lies between grain
        ``j-1`` and ``j``, contacts 0 and N touch the walls (paper Eq. 1).
    delta0 : array, shape (N+1,)
        Static overlaps of the contacts, m; must satisfy force equilibrium
        ``k_j δ0_j^{3/2} = F0`` (checked to 1e-9 relative).
    diameter : float
        Grain diameter d, m (one length unit of the continuum coordinate).
    """

    mass: np.ndarray
    k: np.ndarray
    delta0: np.ndarray
    diameter: float = PAPER_DIAMETER
    info: dict = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        mass = np.asarray(self.mass, dtype=float)
        k = np.asarray(self.k, dtype=float)
        d0 = np.asarray(self.delta0, dtype=float)
        if mass.ndim != 1 or mass.size < 1:
            raise ValueError(f"mass must be a 1-d array of N >= 1 grain masses (got {mass.shape})")
        if k.shape != (mass.size + 1,) or d0.shape != (mass.size + 1,):
            raise ValueError(
                f"k and delta0 need N+1 = {mass.size + 1} contacts (got {k.shape}, {d0.shape})"
            )
        if not (np.all(mass > 0) and np.all(k > 0) and np.all(d0 >= 0)):
            raise ValueError("need mass > 0 kg, k > 0 N/m^1.5 and delta0 >= 0 m everywhere")
        if not np.all(np.isfinite(np.r_[mass, k, d0])) or not self.diameter > 0:
            raise ValueError("mass, k, delta0 must be finite and diameter > 0 m")
        f0 = k * d0**1.5
        if np.ptp(f0) > 1e-9 * max(f0.max(), 1e-300):
            raise ValueError(
                "delta0 violates force equilibrium k δ0^{3/2} = F0 (paper below Eq. 9): "
                f"forces range over [{f0.min():.6g}, {f0.max():.6g}] N"
            )
        object.__setattr__(self, "mass", mass)
        object.__setattr__(self, "k", k)
        object.__setattr__(self, "delta0", d0)
        object.__setattr__(self, "diameter", float(self.diameter))

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_grain_arrays(cls, mass, k, delta0, diameter: float = PAPER_DIAMETER) -> Medium:
        """Medium from per-grain masses and per-contact stiffness/overlap arrays.

        ``delta0`` may be a scalar: it is then the overlap of contact 1 and the others
        follow from force equilibrium (paper, below Eq. 9).
        """
        k = np.asarray(k, dtype=float)
        if np.ndim(delta0) == 0:
            delta0 = _static_overlaps(k, delta0=float(delta0), reference=min(1, k.size - 1))
        return cls(mass=mass, k=k, delta0=delta0, diameter=diameter)

    @classmethod
    def uniform(
        cls,
        n_grains: int,
        delta0: float,
        *,
        material: Material = PAPER_MATERIAL,
        diameter: float = PAPER_DIAMETER,
    ) -> Medium:
        """A monodisperse chain of ``n_grains`` grains with static overlap ``delta0`` (m)."""
        return cls.two_section(n_grains, 0, delta0, material=material, diameter=diameter)

    @classmethod
    def two_section(
        cls,
        n_left: int,
        n_right: int,
        delta0_left: float,
        alpha_rho: float = 1.0,
        alpha_kn: float = 1.0,
        *,
        material: Material = PAPER_MATERIAL,
        diameter: float = PAPER_DIAMETER,
    ) -> Medium:
        """The paper's two-section composite chain (Section 2, Fig. 1).

        Left section: ``material`` (default :data:`theory.PAPER_MATERIAL`, which
        reproduces the paper's numbers with the Hertz constant, docs/physics.md §1); right
        section: ``material.scaled(alpha_rho, alpha_kn)``.  The interface contact
        (between grains ``n_left - 1`` and ``n_left``) has the Hertz constant of the
        unlike pair, the harmonic mean (Johnson 1985, Eq. 4.22); wall contacts are
        treated as grain–grain contacts (paper Section 2).  Static overlaps follow from
        force equilibrium with ``delta0_left`` (m) on the left grain–grain contacts.
        """
        if n_left < 1 or n_right < 0:
            raise ValueError(f"need n_left >= 1 and n_right >= 0 (got {n_left}, {n_right})")
        right = material.scaled(alpha_rho, alpha_kn)
        m_l, m_r = grain_mass(diameter, material.density), grain_mass(diameter, right.density)
        k_l, k_r = hertz_constant(diameter, material), hertz_constant(diameter, right)
        n = n_left + n_right
        mass = np.where(np.arange(n) < n_left, m_l, m_r)
        k = np.where(np.arange(n + 1) <= n_left, k_l, k_r)
        if n_right > 0:
            k[n_left] = hertz_constant(diameter, material, diameter, right)
        d0 = _static_overlaps(k, delta0=float(delta0_left), reference=0)
        info = {"n_left": n_left, "n_right": n_right, "alpha_rho": alpha_rho,
                "alpha_kn": alpha_kn, "delta0_left": float(delta0_left),
                "material": material.name}
        return cls(mass=mass, k=k, delta0=d0, diameter=diameter, info=info)

    # ------------------------------------------------------------------ properties
    @property
    def n_grains(self) -> int:
        """Number of grains N."""
        return int(self.mass.size)

    @property
    def force0(self) -> float:
        """Static contact force F0 = k δ0^{3/2} (paper Eq. 1), N."""
        return float(self.k[0] * self.delta0[0] ** 1.5)

    @property
    def precompressed(self) -> bool:
        """Whether the chain carries a static force (δ0 > 0)."""
        return bool(np.all(self.delta0 > 0))

    def sound_speed(self) -> np.ndarray:
        """Sound speed of each contact's dual cell, c = √(K/m̄) (paper Eq. 4), grains/s.

        ``m̄`` is the mean mass of the two grains of the contact (the wall's grain for
        wall contacts).  Multiply by :attr:`diameter` for m/s.
        """
        m = np.r_[self.mass[0], self.mass, self.mass[-1]]
        m_bar = 0.5 * (m[1:] + m[:-1])
        return np.sqrt(1.5 * self.k * np.sqrt(self.delta0) / m_bar)

    # ------------------------------------------------------------------ discretise
    def discretise(self, n: int, *, periodic: bool = False) -> Discretisation:
        """Node/face coefficients on ``n`` nodes per grain (see module docstring).

        Parameters
        ----------
        n : int
            Nodes per grain, odd and >= 1, so a node sits on every grain centre.
        periodic : bool
            Close the chain on itself; needs ``k[0] == k[N]``.
        """
        if int(n) != n or n < 1 or n % 2 == 0:
            raise ValueError(f"nodes per grain n must be an odd integer >= 1 (got {n})")
        n = int(n)
        ng = self.n_grains
        h = 1.0 / n
        n_nodes = ng * n
        x_nodes = -0.5 + (np.arange(n_nodes) + 0.5) * h
        n_faces = n_nodes if periodic else n_nodes + 1
        x_faces = -0.5 + np.arange(n_faces) * h
        if periodic and not np.isclose(self.k[0], self.k[-1], rtol=1e-12):
            raise ValueError("periodic chains need k[0] == k[N] (the wrap contact)")
        mass = np.repeat(self.mass, n)
        # face q lies in the dual cell (j-1, j) of contact j = ceil(X_q); faces exactly
        # at a contact (X = j - 1/2) have j = round up of that.  No face sits on a grain
        # centre because n is odd.
        j = np.ceil(x_faces - 1e-9 * h).astype(int)
        j = np.clip(j, 0, ng)
        if periodic:
            j[0] = 0
        k = self.k[j]
        f0 = self.force0
        delta0 = (f0 / k) ** (2.0 / 3.0) if f0 > 0 else np.zeros_like(k)
        grain_nodes = np.arange(ng) * n + (n - 1) // 2
        contact_faces = np.arange(ng + 1) * n
        if periodic:
            contact_faces = contact_faces[:-1]
        return Discretisation(
            n=n, h=h, x_nodes=x_nodes, x_faces=x_faces, mass=mass, k=k, delta0=delta0,
            grain_nodes=grain_nodes, contact_faces=contact_faces, periodic=periodic,
        )

    def to_dict(self) -> dict:
        """JSON-friendly summary (for HDF5 attributes)."""
        return {
            "n_grains": self.n_grains,
            "diameter_m": self.diameter,
            "force0_N": self.force0,
            "mass_kg_unique": sorted(set(np.round(self.mass, 15).tolist())),
            "k_unique": sorted(set(np.round(self.k, 3).tolist())),
            **{f"medium_{key}": val for key, val in self.info.items()},
        }
