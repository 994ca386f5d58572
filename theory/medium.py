r"""The coefficients of a chain, built once and read by every model: :class:`Medium`.

A chain of N grains, grain i = 0 … N-1, has N + 1 contacts: contact j lies between
grains j-1 and j, contact 0 touches the left (top) wall and contact N the right
(bottom) one; a free end is an end contact with k = 0 (the convention of
:class:`discrete.Chain`).  The medium holds, as plain arrays,

* the grain masses m_i (kg) and diameters d_i (m),
* the contact constants k_j (N/m^n) and static overlaps δ0_j (m),
* the contact law :math:`F(\delta, \dot\delta; k)` (:mod:`theory.laws`), the on-site
  drag rate β (1/s; force :math:`-m_i\beta\dot u_i`) and gravity g (m/s², along the
  chain from grain 0 to grain N-1),
* the periodic sections (start, stop, cell length) of dimer, trimer, … chains,

and checks the static balance they must satisfy: with :math:`F_{0,j} = F_{el}
(\delta_{0,j}; k_j)` the static contact forces, every grain is in equilibrium under
its weight,

.. math:: F_{0,j+1} - F_{0,j} = m_j g ,

i.e. :math:`F_{0,j} = F_{top} + g\sum_{i<j} m_i` over the present contacts (paper,
below Eq. 9, for g = 0: one force F0 through the chain; Sinkovits & Sen, Phys. Rev.
Lett. 74 (1995) 2686 under gravity).  The dynamic force of a contact is then
:math:`F(\delta_{0,j} + s_j) - F_{0,j}` whatever g: the gradient of the static force
balances the weight, so gravity drops out of every model's equation of motion.

:meth:`discrete.Chain.medium` hands a built chain over; :meth:`Medium.uniform` is the
one-line monodisperse chain of the paper's material (tests, examples).  The continuum
(:mod:`continuum`) discretises a medium in grain-index coordinates; nothing here
depends on a model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._validate import check_array
from .laws import ContactLaw, as_law
from .materials import PAPER_DIAMETER, PAPER_MATERIAL, Material, grain_mass, hertz_constant

__all__ = ["Medium", "EQUILIBRIUM_RTOL"]

EQUILIBRIUM_RTOL = 1e-9
"""Relative tolerance (of the largest static force) of the static-balance check."""


def _scalar(name: str, value, unit: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = math.nan
    if not (math.isfinite(x) and x >= 0):
        raise ValueError(f"{name} must be a finite number >= 0 {unit} (got {value!r}); "
                         "allowed: [0, inf)")
    return x


@dataclass(frozen=True, eq=False)
class Medium:
    r"""A chain's per-grain and per-contact coefficients (module docstring).

    Parameters
    ----------
    mass : array, shape (N,)
        Grain masses, kg (> 0).
    k : array, shape (N+1,)
        Contact constants, N/m^n (> 0 for the grain–grain contacts 1 … N-1; >= 0 at the
        ends, 0 = free end).
    delta0 : array, shape (N+1,)
        Static overlaps, m (>= 0; 0 where k = 0); in static balance (module docstring,
        checked to :data:`EQUILIBRIUM_RTOL` of the largest static force).
    diameter : float or array, shape (N,)
        Grain diameters, m (> 0): the unit of the continuum's length per grain.
    law : ContactLaw, optional
        The contact law (default :data:`theory.laws.HERTZ`, paper Eq. 1).
    drag : float
        On-site drag rate β, 1/s (>= 0).
    gravity : float
        Acceleration of gravity from grain 0 towards grain N-1, m/s² (>= 0).
    cells : sequence of (start, stop, length)
        Periodic sections: grains start … stop-1 repeat a unit cell of ``length`` grains
        (from ``start``; the last cell may be cut).
    info : dict
        JSON-able description of how the medium was built (not compared).
    """

    mass: np.ndarray
    k: np.ndarray
    delta0: np.ndarray
    diameter: np.ndarray | float = PAPER_DIAMETER
    law: ContactLaw | None = None
    drag: float = 0.0
    gravity: float = 0.0
    cells: tuple = ()
    info: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        m = np.asarray(self.mass)
        if m.ndim != 1 or m.size < 1:
            raise ValueError(f"mass must be a 1-d array of N >= 1 grain masses "
                             f"(got shape {m.shape})")
        n = m.size
        mass = check_array("mass", self.mass, n)
        k = check_array("k", self.k, n + 1)
        d0 = check_array("delta0", self.delta0, n + 1)
        diam = check_array("diameter", self.diameter, n)
        if np.any(mass <= 0):
            raise ValueError(f"mass must be > 0 kg (min {mass.min()!r}); allowed: (0, inf)")
        if np.any(diam <= 0):
            raise ValueError(f"diameter must be > 0 m (min {diam.min()!r}); allowed: (0, inf)")
        if np.any(k < 0) or np.any(k[1:-1] <= 0):
            raise ValueError("k must be > 0 N/m^n at the grain-grain contacts 1..N-1 and "
                             ">= 0 at the ends (0: a free end)")
        if np.any(d0 < 0):
            raise ValueError(f"delta0 must be >= 0 m (min {d0.min()!r}); allowed: [0, inf)")
        if np.any((k == 0) & (d0 != 0)):
            raise ValueError("delta0 must be 0 at an absent end contact (k = 0)")
        law = as_law(self.law)
        object.__setattr__(self, "mass", mass)
        object.__setattr__(self, "k", k)
        object.__setattr__(self, "delta0", d0)
        object.__setattr__(self, "diameter", diam)
        object.__setattr__(self, "law", law)
        object.__setattr__(self, "drag", _scalar("drag", self.drag, "1/s"))
        object.__setattr__(self, "gravity", _scalar("gravity", self.gravity, "m/s^2"))
        object.__setattr__(self, "cells", self._check_cells(self.cells, n))
        self._check_balance()

    @staticmethod
    def _check_cells(cells, n: int) -> tuple:
        out = []
        for c in cells:
            try:
                start, stop, length = (int(x) for x in c)
            except (TypeError, ValueError):
                raise ValueError(f"cells must be (start, stop, length) triples of "
                                 f"integers (got {c!r})") from None
            if not (0 <= start < stop <= n and length >= 1):
                raise ValueError(f"cell section {c!r} must satisfy 0 <= start < stop <= "
                                 f"N = {n} and length >= 1")
            out.append((start, stop, length))
        spans = sorted(out)
        for (_, b, _), (a, _, _) in zip(spans, spans[1:], strict=False):
            if a < b:
                raise ValueError(f"cell sections overlap: {spans}")
        return tuple(out)

    def _check_balance(self) -> None:
        """Raise unless F0_j - g Σ_{i<j} m_i is one force over the present contacts."""
        f0 = self.f0
        present = self.k > 0
        top = f0 - self.gravity * np.r_[0.0, np.cumsum(self.mass)]
        top = top[present]
        scale = max(float(np.max(f0[present], initial=0.0)), 1e-300)
        if np.ptp(top) > EQUILIBRIUM_RTOL * scale:
            what = ("F0_j - g sum_{i<j} m_i" if self.gravity else "F0_j = k_j delta0_j^n")
            raise ValueError(
                f"delta0 violates the static balance F0_(j+1) - F0_j = m_j g (paper below "
                f"Eq. 9; g = {self.gravity:g} m/s^2, law: {self.law.describe()}): {what} "
                f"ranges over [{top.min():.6g}, {top.max():.6g}] N")

    # ------------------------------------------------------------------ constructors
    @classmethod
    def uniform(cls, n_grains: int, delta0: float, *, material: Material = PAPER_MATERIAL,
                diameter: float = PAPER_DIAMETER, law: ContactLaw | None = None) -> Medium:
        """``n_grains`` identical grains of ``material``, static overlap ``delta0`` (m).

        Mass (π/6) d³ ρ and the two-sphere Hertz constant (Johnson 1985, Eq. 4.22) on
        every contact, the wall contacts included (the paper's walls, Section 2).
        """
        if not (isinstance(n_grains, int | np.integer) and n_grains >= 1):
            raise ValueError(f"n_grains must be an integer >= 1 (got {n_grains!r})")
        d0 = _scalar("delta0", delta0, "m")
        m = float(grain_mass(diameter, material.density))
        k = float(hertz_constant(diameter, material))
        return cls(np.full(n_grains, m), np.full(n_grains + 1, k),
                   np.full(n_grains + 1, d0), diameter, law=law,
                   info={"kind": "uniform", "material": material.name})

    # ------------------------------------------------------------------ properties
    @property
    def n_grains(self) -> int:
        """Number of grains N."""
        return int(self.mass.size)

    @property
    def present(self) -> np.ndarray:
        """Which contacts exist (k > 0), shape (N+1,)."""
        return self.k > 0

    @property
    def f0(self) -> np.ndarray:
        """Static contact forces F_el(δ0_j; k_j), N (0 at a free end)."""
        return np.where(self.present, self.law.elastic(self.delta0, self.k), 0.0)

    @property
    def stiffness(self) -> np.ndarray:
        """Linear stiffness ∂F_el/∂δ at δ0 per contact, N/m (paper Eq. 4's K for Hertz)."""
        return self.law.stiffness(self.delta0, self.k)

    @property
    def precompressed(self) -> bool:
        """Whether every present contact carries a static overlap (δ0 > 0)."""
        return bool(np.all(self.delta0[self.present] > 0))

    @property
    def sonic_vacuum(self) -> bool:
        """Whether no contact carries a static overlap (δ0 = 0 everywhere)."""
        return not np.any(self.delta0 > 0)

    @property
    def dissipative(self) -> bool:
        """Velocity-dependent forces: a dissipative law or on-site drag."""
        return bool(self.law.dissipative or self.drag > 0)

    def sound_speed(self) -> np.ndarray:
        """Sound speed √(K_j/m̄_j) of each contact's dual cell, grains/s (paper Eq. 4).

        m̄_j is the mean mass of the contact's two grains (the one grain at an end).
        Multiply by the local diameter for m/s.
        """
        m = np.r_[self.mass[0], self.mass, self.mass[-1]]
        return np.sqrt(self.stiffness / (0.5 * (m[1:] + m[:-1])))

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly summary (for HDF5 attributes)."""
        f0 = self.f0
        return {
            "n_grains": self.n_grains,
            "diameter_m_range": [float(self.diameter.min()), float(self.diameter.max())],
            "force0_N_range": [float(f0[self.present].min()), float(f0[self.present].max())],
            "mass_kg_unique": sorted(set(np.round(self.mass, 15).tolist()))[:16],
            "k_unique": sorted(set(np.round(self.k, 3).tolist()))[:16],
            "law": self.law.to_dict(),
            "drag_1_s": self.drag,
            "gravity_m_s2": self.gravity,
            "cells": [list(c) for c in self.cells],
            **{f"medium_{key}": val for key, val in self.info.items()},
        }
