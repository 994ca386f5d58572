r"""Continuum solutions sampled grain by grain, for comparison with the discrete solver.

Because the number of nodes per grain is odd, a node sits on every grain centre, so
grain displacements and velocities are read off without interpolation.  Everything
else is then computed with the *discrete* chain's formulas (paper Eq. 1, 2), so that a
continuum run and a DEM run are compared with identical definitions:

* overlap of contact j: δ_j = δ0_j + u_{j-1} - u_j (walls at rest; a free end keeps
  δ0; periodic chains wrap), m — or the model's own overlap of that contact where the
  model defines one (``contact_overlaps(u)``: the quasi-continuum's averaged strain,
  :class:`continuum.GrainAveragedPDE`);
* kinetic energy of grain i: ½ m_i v_i², J;
* potential energy of contact j: the contact energy minus the static energy of the same
  contact, U(δ_j) - U(δ0_j) with U the law's elastic energy (Hertz: (2/5) k_j
  ([δ_j]_+^{5/2} - δ0_j^{5/2})), J (paper Table 2, docs/physics.md §6 — it keeps the
  linear term F0_j (δ_j - δ0_j), so an expansive wave has negative potential energy);
* under gravity (a body force m_i g per grain) the potential energy of contact j also
  holds the body force's share, −W_j (δ_j − δ0_j) with W_j = g Σ_{i<j} m_i the weight
  above it: summed over the chain (walls at rest) it is −g Σ_i m_i u_i, the body force's
  potential energy, so that the sum is the energy the discrete chain conserves
  (:func:`hertzchain.measure.grain_energies` uses the same definition); zero without
  gravity;
* energy of grain i: kinetic plus half of each of its two contacts.

In a homogenised periodic section (:mod:`continuum.cells`) the equation carries the
cell's mean overlap; a contact's own overlap is then the one at which its constant
k_j carries the homogenised force, (F/k_j)^{1/n} (the cell's contacts share the force
at leading order).

The continuum equations conserve their own functionals
(:meth:`~continuum.base.ChainPDEBase.energy`); the grain-sampled energies agree with
them only to the accuracy of the long-wave approximation, O(d²/L²) for a wave of width
L: ~1e-4 for the paper's precompressed wave (L ≈ 5 d, Table-2 points M, N),
0.7 % for the squeezed wave of point P, and up to 10 % for sonic-vacuum waves (5 grains
wide, energy ∝ δ^{5/2}) — there, compare energies through the functional.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["GrainSample", "sample_grains", "section_energies"]


@dataclass(frozen=True)
class GrainSample:
    """A continuum state sampled at the grains (arrays per grain or per contact).

    Attributes
    ----------
    u, v : numpy.ndarray, shape (N,)
        Grain displacement (m) and velocity (m/s).
    overlap : numpy.ndarray, shape (N+1,)
        Contact overlaps δ_j, m.
    kinetic : numpy.ndarray, shape (N,)
        ½ m v², J.
    potential : numpy.ndarray, shape (N+1,)
        U(δ) - U(δ0) per contact (the law's elastic energy; Hertz (2/5) k ([δ]_+^{5/2}
        - δ0^{5/2})), minus W (δ - δ0) under gravity (module docstring), J.
    force : numpy.ndarray, shape (N+1,)
        Elastic contact force F_el(δ) (Hertz k [δ]_+^{3/2}), N.
    delta0 : numpy.ndarray, shape (N+1,)
        Static overlaps, m.
    force0 : numpy.ndarray, shape (N+1,)
        Static contact forces F0_j, N (one value through the chain without gravity).
    """

    u: np.ndarray
    v: np.ndarray
    overlap: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    force: np.ndarray
    delta0: np.ndarray
    force0: np.ndarray

    @property
    def grain_energy(self) -> np.ndarray:
        """Kinetic energy plus half of each adjacent contact's potential energy, J."""
        return self.kinetic + 0.5 * (self.potential[:-1] + self.potential[1:])

    @property
    def strain(self) -> np.ndarray:
        """Dynamic overlap change δ_j - δ0_j, m."""
        return self.overlap - self.delta0


def sample_grains(pde, state) -> GrainSample:
    """Sample a chain-PDE state (u, v) at the grains (see module docstring).

    Parameters
    ----------
    pde : ChainPDEBase
        The equation whose state it is (gives medium, nodes and boundary condition).
    state : FieldCollection
        The state (u, v).
    """
    med, disc = pde.medium, pde.disc
    u = np.asarray(state[0].data)[disc.grain_nodes].copy()
    v = np.asarray(state[1].data)[disc.grain_nodes].copy()
    du = np.empty(med.n_grains + 1)
    du[1:-1] = u[:-1] - u[1:]
    if pde.bc == "wall":
        du[0], du[-1] = -u[0], u[-1]
    elif pde.bc == "free":
        du[0] = du[-1] = 0.0
    else:
        du[0] = du[-1] = u[-1] - u[0]
    law = med.law
    overlap = med.delta0 + du
    own = getattr(pde, "contact_overlaps", None)
    if own is not None:  # a model whose contact overlap is its own averaged strain
        overlap = own(np.asarray(state[0].data))
    eff = pde.effective
    cells = eff.k != med.k
    if np.any(cells):
        # homogenised cells: the contact's own overlap under the homogenised force
        force = law.elastic(eff.delta0[cells] + du[cells], eff.k[cells])
        overlap[cells] = np.where(force > 0, law.static_overlap(force, med.k[cells]),
                                  eff.delta0[cells] + du[cells])
    potential = law.energy(overlap, med.k, med.delta0)
    if med.gravity:  # the body force's potential energy, per contact (module docstring)
        potential = potential - med.gravity * np.r_[0.0, np.cumsum(med.mass)] * (
            overlap - med.delta0)
    return GrainSample(
        u=u, v=v, overlap=overlap,
        kinetic=0.5 * med.mass * v * v,
        potential=potential,
        force=law.elastic(overlap, med.k),
        delta0=med.delta0.copy(),
        force0=med.f0,
    )


def section_energies(sample: GrainSample, n_left: int) -> dict[str, dict[str, float]]:
    """Kinetic, potential and total energy left and right of contact ``n_left``, J.

    The interface contact (between grains ``n_left - 1`` and ``n_left``) is split half
    to each side (docs/physics.md §6: once the waves have separated its share is negligible).
    ``potential_linear`` is the linear part of the potential energy,
    Σ F0_j (δ_j - δ0_j), used by :func:`theory.table2_prediction`.
    """
    pot, lin = sample.potential, sample.force0 * sample.strain
    out = {}
    for side, grains, contacts, half in (
        ("left", slice(0, n_left), slice(0, n_left), n_left),
        ("right", slice(n_left, None), slice(n_left + 1, None), n_left),
    ):
        ek = float(sample.kinetic[grains].sum())
        ep = float(pot[contacts].sum() + 0.5 * pot[half])
        out[side] = {"kinetic": ek, "potential": ep, "total": ek + ep,
                     "potential_linear": float(lin[contacts].sum() + 0.5 * lin[half])}
    return out
