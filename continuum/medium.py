r"""The chain as a continuous medium: its coefficients on the staggered grid.

The medium itself — grain masses, contact constants and static overlaps, the contact
law, drag and gravity — is :class:`theory.medium.Medium` (re-exported here as
:class:`continuum.Medium`), built once per chain and read by every model
(:meth:`discrete.Chain.medium`).  This module places its coefficients on the grid.

Coordinates
-----------
Lengths along the chain are measured in grains, ``X`` = grain index (``X = x/d`` for
identical grains), so grain ``i`` sits at ``X = i`` and contact ``j`` (between grains
``j-1`` and ``j``; contact 0 and contact N touch the walls) at ``X = j - 1/2``, whatever
the diameters: the discrete equations of motion (paper Eq. 2) contain no positions,
only masses and contact laws, so in grain-index coordinates a tapered or polydisperse
chain is a medium of variable coefficients and its long-wave dispersion length is
that of the lattice, ℓ² = 1/12 grains² (docs/physics.md, "Long waves on any chain").
Displacements ``u`` stay in metres and time in seconds, so continuum fields line up
with the discrete solver's ``u_i(t)``, ``v_i(t)`` grain by grain.

Discretisation (staggered, conservative)
----------------------------------------
``n`` nodes per grain (``n`` odd) at ``X_p = -1/2 + (p + 1/2)/n`` carry ``u`` and
``v``; faces at ``X_q = -1/2 + q/n`` carry the strain and the contact force.  Because
``n`` is odd a node sits exactly on every grain centre and every contact is a face,
so

* the mass of node ``p`` is the mass of the grain whose cell ``[i-1/2, i+1/2]``
  contains it, and
* the constants (k, δ0, the dispersion ratio) of face ``q`` are those of the contact
  whose *dual cell* ``(j-1, j)`` (from grain centre to grain centre) contains the face;
  a free end (k = 0) lends its half dual cell the constants of the next contact.

This reproduces the chain's total mass ``Σ m_i`` and, for a linear law, total
compliance ``Σ 1/K_j`` exactly, for any ``n``; a material interface is a jump of the
mass at a contact face and of the constants at the grain centres either side of the
interface contact, whose own constants fill the dual cell between them.  Each face
keeps its contact's static overlap and static force F0_j (which vary along the chain
under gravity, :mod:`theory.medium`): the flux is the dynamic force F(δ0_j + s) − F0_j.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from theory.laws import ContactLaw
from theory.medium import Medium

__all__ = ["Medium", "Discretisation", "BOUNDARY_CONDITIONS", "discretise"]

BOUNDARY_CONDITIONS = ("free", "wall", "periodic")
"""Supported boundary conditions of the continuum solvers.

``"free"``: the end carries its static force F0 but no dynamic force (a constant-load
piston, or a free end; the natural boundary condition, zero dynamic flux).  ``"wall"``:
a rigid wall at ``X = -1/2`` (``N - 1/2``) with ``u = 0`` (needs both end contacts).
``"periodic"``: the chain closes on itself (contact 0 = contact N; ``u`` must then be
periodic)."""


@dataclass(frozen=True)
class Discretisation:
    """Node and face coefficients of a :class:`Medium` on ``n`` nodes per grain.

    Attributes
    ----------
    n : int
        Nodes per grain (odd).
    h : float
        Node spacing, grains (= 1/n).
    x_nodes : numpy.ndarray
        Node positions, grains.
    x_faces : numpy.ndarray
        Face positions, grains (``N n + 1`` faces; ``N n`` if periodic).
    mass : numpy.ndarray
        Grain mass assigned to each node, kg.
    k : numpy.ndarray
        Contact constant of each face, N/m^n.
    delta0 : numpy.ndarray
        Static overlap of each face, m.
    dispersion : numpy.ndarray
        Dispersion ratio of each face: its long-wave dispersion length² over the
        lattice's 1/12 grains² (1, except in homogenised periodic sections,
        :mod:`continuum.cells`).
    contact : numpy.ndarray
        Index of the contact whose constants each face carries.
    grain_nodes : numpy.ndarray
        Index of the node at each grain centre.
    contact_faces : numpy.ndarray
        Index of the face at each contact.
    periodic : bool
        Whether the domain is periodic.
    law : ContactLaw
        The contact law.
    """

    n: int
    h: float
    x_nodes: np.ndarray
    x_faces: np.ndarray
    mass: np.ndarray
    k: np.ndarray
    delta0: np.ndarray
    dispersion: np.ndarray
    contact: np.ndarray
    grain_nodes: np.ndarray
    contact_faces: np.ndarray
    periodic: bool
    law: ContactLaw

    @property
    def f0(self) -> np.ndarray:
        """Static force F_el(δ0; k) of each face, N (NumPy twin of the law)."""
        return self.law.elastic(self.delta0, self.k)

    @property
    def stiffness(self) -> np.ndarray:
        """Linearised face stiffness K = ∂F_el/∂δ at δ0, N/m ((3/2) k δ0^{1/2}: Eq. 4)."""
        return self.law.stiffness(self.delta0, self.k)

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


def discretise(medium: Medium, n: int, *, periodic: bool = False,
               dispersion=None) -> Discretisation:
    """Node/face coefficients of ``medium`` on ``n`` nodes per grain (module docstring).

    Parameters
    ----------
    medium : Medium
        The chain.
    n : int
        Nodes per grain, odd and >= 1, so a node sits on every grain centre.
    periodic : bool
        Close the chain on itself; needs the same end contacts (k[0] == k[N], δ0 too).
    dispersion : array of shape (N+1,), optional
        Dispersion ratio per contact (default 1: the lattice's ℓ² = 1/12).
    """
    if int(n) != n or n < 1 or n % 2 == 0:
        raise ValueError(f"nodes per grain n must be an odd integer >= 1 (got {n})")
    n = int(n)
    ng = medium.n_grains
    h = 1.0 / n
    n_nodes = ng * n
    x_nodes = -0.5 + (np.arange(n_nodes) + 0.5) * h
    n_faces = n_nodes if periodic else n_nodes + 1
    x_faces = -0.5 + np.arange(n_faces) * h
    k_c, d0_c = medium.k.copy(), medium.delta0.copy()
    disp_c = np.ones(ng + 1) if dispersion is None else np.array(dispersion, float)
    if disp_c.shape != (ng + 1,) or not np.all(np.isfinite(disp_c) & (disp_c > 0)):
        raise ValueError(f"dispersion must be {ng + 1} finite ratios > 0 (one per contact)")
    if periodic:
        if not (np.isclose(k_c[0], k_c[-1], rtol=1e-12, atol=0)
                and np.isclose(d0_c[0], d0_c[-1], rtol=1e-12, atol=0)):
            raise ValueError("periodic chains need k[0] == k[N] and delta0[0] == delta0[N] "
                             "(the wrap contact)")
    if ng > 1:
        # a free end (k = 0): its half dual cell carries the next contact's constants
        for end, nb in ((0, 1), (ng, ng - 1)):
            if k_c[end] == 0:
                k_c[end], d0_c[end], disp_c[end] = k_c[nb], d0_c[nb], disp_c[nb]
    elif np.any(k_c == 0):
        raise ValueError("a one-grain medium needs both end contacts (k > 0)")
    # face q lies in the dual cell (j-1, j) of contact j = ceil(X_q); faces exactly
    # at a contact (X = j - 1/2) have j = round up of that.  No face sits on a grain
    # centre because n is odd.
    j = np.ceil(x_faces - 1e-9 * h).astype(int)
    j = np.clip(j, 0, ng)
    if periodic:
        j[0] = 0
    grain_nodes = np.arange(ng) * n + (n - 1) // 2
    contact_faces = np.arange(ng + 1) * n
    if periodic:
        contact_faces = contact_faces[:-1]
    return Discretisation(
        n=n, h=h, x_nodes=x_nodes, x_faces=x_faces, mass=np.repeat(medium.mass, n),
        k=k_c[j], delta0=d0_c[j], dispersion=disp_c[j], contact=j,
        grain_nodes=grain_nodes, contact_faces=contact_faces, periodic=periodic,
        law=medium.law,
    )
