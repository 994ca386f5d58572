r"""The chain: per-grain masses and per-contact Hertz constants and static overlaps.

A chain of N spheres, grain i = 0 … N-1, has N + 1 contacts: contact j lies between
grain j-1 and grain j, contact 0 between the left wall and grain 0, contact N between
grain N-1 and the right wall.  A free end is a wall contact with k = 0.  The contact law
is the paper's Eq. 1, :math:`F_j = k_j [\delta_j]_+^{3/2}` (N), with the overlap

.. math::
    \delta_j = \delta_{0,j} + u_{j-1} - u_j ,\qquad
    \delta_0 = \delta_{0,0} + w_L - u_0 ,\qquad
    \delta_N = \delta_{0,N} + u_{N-1} - w_R ,

u the displacements from static equilibrium (m) and :math:`w_{L,R}` the wall
displacements (m).  In static equilibrium every contact carries the same force
:math:`F_0 = k_j\delta_{0,j}^{3/2}` (paper, below Eq. 9), so
:math:`\delta_{0,j} = (F_0/k_j)^{2/3}` (:func:`theory.static_overlaps`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

import theory
from theory import Material
from theory._validate import check_array

__all__ = ["Chain", "Section", "Tapered", "Periodic", "Disorder", "WallKind"]

WallKind = Literal["paper", "hertz", "flat"] | Material | None
"""A wall contact: ``"paper"`` (the grain–grain constant), ``"hertz"`` (a rigid flat),
``"flat"`` (a flat of the adjacent grain's own material), a :class:`theory.Material`
(a flat of that material) or None (a free end)."""


@dataclass(frozen=True)
class Tapered:
    """Per-grain profile: grain masses shrink (or grow) by ``mass_ratio`` from grain to grain.

    m_{i+1}/m_i = q along the section, left to right, at fixed material: diameters
    d_i = d q^{i/3}.  q < 1 is a *forward* taper for a wave travelling right (large to
    small grains; Sen, Manciu & Wright, Phys. Rev. E 57 (1998) 2386; Doney & Sen, Phys.
    Rev. Lett. 97 (2006) 155502), q > 1 a backward one.
    """

    mass_ratio: float

    def __post_init__(self) -> None:
        _positive_scalar("Tapered.mass_ratio", self.mass_ratio)

    def grains(self, n: int, diameter: float, material: Material):
        """Per-grain (diameters, materials) of a section of ``n`` grains."""
        return diameter * float(self.mass_ratio) ** (np.arange(n) / 3.0), [material] * n

    def to_dict(self) -> dict:
        """JSON-able description."""
        return {"profile": "tapered", "mass_ratio": float(self.mass_ratio)}


@dataclass(frozen=True)
class Periodic:
    """Per-grain profile: a repeated unit cell (dimer, trimer, …).

    ``cell`` lists (diameter factor, material) per grain of the cell; the factor
    multiplies the section's diameter and a material of ``None`` is the section's.
    A dimer of equal materials with mass ratio ε: ``Periodic(((1.0, None),
    (ε ** (1/3), None)))``.  The section's grain count need not be a multiple of the
    cell length (the last cell is cut).
    """

    cell: tuple

    def __post_init__(self) -> None:
        cell = tuple(tuple(c) for c in self.cell)
        if not cell or any(len(c) != 2 for c in cell):
            raise ValueError("Periodic.cell must be a non-empty sequence of "
                             "(diameter factor, material or None) pairs")
        for f, m in cell:
            _positive_scalar("Periodic.cell diameter factor", f)
            if m is not None and not isinstance(m, Material):
                raise ValueError(f"Periodic.cell material must be a theory.Material or None "
                                 f"(got {m!r})")
        object.__setattr__(self, "cell", cell)

    def grains(self, n: int, diameter: float, material: Material):
        """Per-grain (diameters, materials) of a section of ``n`` grains."""
        idx = np.arange(n) % len(self.cell)
        d = np.array([diameter * float(self.cell[q][0]) for q in idx])
        mats = [self.cell[q][1] or material for q in idx]
        return d, mats

    def to_dict(self) -> dict:
        """JSON-able description."""
        return {"profile": "periodic",
                "cell": [[float(f), None if m is None else _material_dict(m)]
                         for f, m in self.cell]}


@dataclass(frozen=True)
class Disorder:
    """Seeded random disorder of a section's masses, contact stiffnesses and diameters.

    Each quantity is multiplied by an independent factor 1 + σ√3 U, U uniform in
    [-1, 1] (relative standard deviation σ, in [0, 0.5]): ``diameter`` changes the
    grains (mass ∝ d³ and the Hertz constants follow), ``mass`` the masses alone (a
    density defect), ``stiffness`` the grain–grain contact constants alone.
    """

    mass: float = 0.0
    stiffness: float = 0.0
    diameter: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("mass", "stiffness", "diameter"):
            x = getattr(self, name)
            if not (isinstance(x, int | float) and 0.0 <= x <= 0.5):
                raise ValueError(f"Disorder.{name} must be in [0, 0.5] (got {x!r})")
        if not isinstance(self.seed, int | np.integer):
            raise ValueError(f"Disorder.seed must be an integer (got {self.seed!r})")

    def factors(self, n: int) -> dict[str, np.ndarray]:
        """The random factors (mass, stiffness, diameter) of ``n`` grains (contacts)."""
        rng = np.random.default_rng(int(self.seed))
        s3 = math.sqrt(3.0)
        return {name: 1.0 + getattr(self, name) * s3 * rng.uniform(-1.0, 1.0, n)
                for name in ("diameter", "mass", "stiffness")}

    def to_dict(self) -> dict:
        """JSON-able description."""
        return {"mass": float(self.mass), "stiffness": float(self.stiffness),
                "diameter": float(self.diameter), "seed": int(self.seed)}


@dataclass(frozen=True)
class Section:
    """A run of ``n`` grains of diameter ``diameter`` (m) and ``material``.

    ``profile`` (:class:`Tapered`, :class:`Periodic`; None: identical grains) varies
    diameters and materials per grain; ``disorder`` (:class:`Disorder`) perturbs them.
    """

    n: int
    diameter: float
    material: Material
    profile: Tapered | Periodic | None = None
    disorder: Disorder | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.n, int | np.integer) or self.n < 1:
            raise ValueError(f"Section.n must be an integer >= 1 (got {self.n!r})")
        _positive_scalar("Section.diameter", self.diameter)
        if not isinstance(self.material, Material):
            raise ValueError(f"Section.material must be a theory.Material (got {self.material!r})")
        if self.profile is not None and not isinstance(self.profile, Tapered | Periodic):
            raise ValueError(f"Section.profile must be Tapered, Periodic or None "
                             f"(got {self.profile!r})")
        if self.disorder is not None and not isinstance(self.disorder, Disorder):
            raise ValueError(f"Section.disorder must be a Disorder or None "
                             f"(got {self.disorder!r})")

    @property
    def uniform(self) -> bool:
        """All grains identical (no profile, no disorder)."""
        return self.profile is None and self.disorder is None

    @property
    def mass(self) -> float:
        """Grain mass (π/6) d³ ρ, kg (paper Section 2), of the section's nominal grain."""
        return float(theory.grain_mass(self.diameter, self.material.density))

    @property
    def kn(self) -> float:
        """Hertz constant of two nominal grains, N/m^{3/2} (Johnson Eq. 4.22)."""
        return float(theory.hertz_constant(self.diameter, self.material))

    def grains(self):
        """Per-grain (diameters, materials, mass factors, stiffness factors).

        Arrays of the n grains (materials: a list); the stiffness factor of grain i is
        that of the contact on its left.
        """
        n = int(self.n)
        if self.profile is None:
            d, mats = np.full(n, float(self.diameter)), [self.material] * n
        else:
            d, mats = self.profile.grains(n, float(self.diameter), self.material)
        fm = fk = np.ones(n)
        if self.disorder is not None:
            f = self.disorder.factors(n)
            d, fm, fk = d * f["diameter"], f["mass"], f["stiffness"]
        return d, mats, fm, fk

    def to_dict(self) -> dict:
        """JSON-able description (chain ``params``)."""
        out = {"n": int(self.n), "diameter": float(self.diameter),
               "material": _material_dict(self.material)}
        if self.profile is not None:
            out["profile"] = self.profile.to_dict()
        if self.disorder is not None:
            out["disorder"] = self.disorder.to_dict()
        return out


def _material_dict(m: Material) -> dict:
    return {"density": m.density, "youngs_modulus": m.youngs_modulus,
            "poisson_ratio": m.poisson_ratio, "name": m.name}


def _positive_scalar(name: str, value) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a real number > 0 (got {value!r})") from exc
    if not math.isfinite(x) or x <= 0:
        raise ValueError(f"{name} must be finite and > 0 (got {value!r}); allowed: (0, inf)")
    return x


def _wall_k(kind: WallKind, side: str, diameter: float, material: Material) -> float:
    """Constant of the wall contact of a grain (diameter m, material), N/m^{3/2}.

    A flat wall of a material (``"flat"``: the grain's own; a :class:`theory.Material`)
    has R* = d/2 and E* from both materials (Johnson 1985, Eq. 4.22;
    :func:`theory.hertz_constant_wall`).
    """
    if kind is None:
        return 0.0
    if isinstance(kind, Material):
        return float(theory.hertz_constant_wall(float(diameter), material, kind))
    if kind == "paper":
        return float(theory.hertz_constant(float(diameter), material))
    if kind == "hertz":
        return float(theory.hertz_constant_wall(float(diameter), material))
    if kind == "flat":
        return float(theory.hertz_constant_wall(float(diameter), material, material))
    raise ValueError(f"{side}_wall must be 'paper', 'hertz', 'flat', a Material or None "
                     f"(got {kind!r})")


def _wall_param(kind: WallKind):
    """A wall kind as JSON-able chain parameters (a material: its name and values)."""
    if isinstance(kind, Material):
        return {"flat": _material_dict(kind)}
    return kind


def _pair_k(d1, m1, d2, m2) -> np.ndarray:
    """Two-sphere Hertz constants of grain pairs (arrays of diameters, lists of materials).

    The arithmetic of :func:`theory.hertz_constant` (Johnson 1985, Eq. 4.22), per pair.
    """
    def props(ms, name):
        return np.array([getattr(m, name) for m in ms], dtype=float)

    r1, r2 = np.asarray(d1, float) / 2, np.asarray(d2, float) / 2
    r_eff = r1 * r2 / (r1 + r2)
    e_eff = theory.effective_modulus(props(m1, "youngs_modulus"), props(m1, "poisson_ratio"),
                                     props(m2, "youngs_modulus"), props(m2, "poisson_ratio"))
    return 4.0 / 3.0 * np.asarray(e_eff) * np.sqrt(r_eff)


def _gravity_overlaps(k, mass, top_force: float, g: float, exponent: float) -> np.ndarray:
    """Static overlaps under gravity: F_j = F_top + g Σ_{i<j} m_i, δ_j = (F_j/k_j)^{1/n}."""
    f = top_force + g * np.r_[0.0, np.cumsum(mass)]
    out = np.zeros_like(k)
    present = k > 0
    n = float(exponent)
    if n == 1.5:
        out[present] = (f[present] / k[present]) ** (2.0 / 3.0)
    else:
        out[present] = (f[present] / k[present]) ** (1.0 / n)
    return out


@dataclass(frozen=True, eq=False)
class Chain:
    """A 1-D chain of Hertzian spheres between two walls (or free ends).

    Parameters
    ----------
    mass : (N,) array
        Grain masses, kg (> 0).
    k : (N+1,) array
        Contact constants of Eq. 1, N/m^n for the law F = k δⁿ (N/m^{3/2} for Hertz;
        >= 0); contact j couples grains j-1 and j, contact 0 the left wall, contact N
        the right wall; 0 = no contact (free end).
    delta0 : (N+1,) array
        Static overlaps, m (>= 0; 0 where k = 0).
    diameter : (N,) array
        Grain diameters, m (> 0); used for positions and strains only.
    section : (N,) int array
        Section index of every grain.
    params : dict
        JSON-able description of how the chain was built.
    """

    mass: np.ndarray
    k: np.ndarray
    delta0: np.ndarray
    diameter: np.ndarray
    section: np.ndarray
    params: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        m = np.asarray(self.mass)
        if m.ndim != 1 or m.size < 2:
            raise ValueError(f"a chain needs N >= 2 grains (got mass of shape {m.shape})")
        n = m.size
        object.__setattr__(self, "mass", check_array("mass", self.mass, n, positive=True))
        object.__setattr__(self, "k", check_array("k", self.k, n + 1, nonneg=True))
        object.__setattr__(self, "delta0", check_array("delta0", self.delta0, n + 1, nonneg=True))
        object.__setattr__(self, "diameter",
                           check_array("diameter", self.diameter, n, positive=True))
        sec = np.array(self.section, dtype=np.int64)
        if sec.ndim == 0:
            sec = np.full(n, int(sec))
        if sec.shape != (n,):
            raise ValueError(f"section must have shape ({n},) (got {sec.shape})")
        sec.setflags(write=False)
        object.__setattr__(self, "section", sec)
        if np.any(self.k[1:-1] <= 0):
            raise ValueError("k of the grain-grain contacts 1..N-1 must be > 0")
        if np.any((self.k == 0) & (self.delta0 != 0)):
            raise ValueError("delta0 must be 0 at an absent contact (k = 0)")
        if np.any(self.delta0 > 0.5 * np.minimum(
                np.r_[self.diameter[0], self.diameter], np.r_[self.diameter, self.diameter[-1]])):
            raise ValueError("delta0 must be below half the grain diameter (Hertz small-strain)")
        if np.any(self.delta0 > 0) and (self.k[0] == 0 or self.k[-1] == 0) \
                and self.gravity == 0:
            raise ValueError("a precompressed chain (delta0 > 0) needs both walls (k[0], k[N] > 0)")

    # ------------------------------------------------------------------ properties
    @property
    def n(self) -> int:
        """Number of grains N."""
        return int(self.mass.size)

    @property
    def gravity(self) -> float:
        """Acceleration of gravity from grain 0 towards grain N-1, m/s² (``params``; 0)."""
        return float(self.params.get("gravity", 0.0))

    @property
    def body_force(self) -> np.ndarray:
        """Body force on each grain, m_i g, N (towards grain N-1)."""
        return self.mass * self.gravity

    @property
    def exponent(self) -> float:
        """Exponent n of the contact law the static overlaps balance (``params``; 3/2)."""
        return float(self.params.get("exponent", 1.5))

    @property
    def f0(self) -> np.ndarray:
        """Static contact forces k δ0^n, N (Eq. 1 for n = 3/2, as the kernels compute it)."""
        if self.exponent == 1.5:
            return self.k * (self.delta0 * np.sqrt(self.delta0))
        return self.k * self.delta0**self.exponent

    @property
    def positions(self) -> np.ndarray:
        """Grain-centre positions in the uncompressed chain, m (grain 0 at d_0/2)."""
        d = self.diameter
        return np.cumsum(d) - d / 2

    def section_slices(self) -> list[slice]:
        """Slices of consecutive grains with the same section index."""
        edges = np.flatnonzero(np.diff(self.section)) + 1
        b = np.r_[0, edges, self.n]
        return [slice(int(b[i]), int(b[i + 1])) for i in range(b.size - 1)]

    # ---------------------------------------------------------------- constructors
    @classmethod
    def from_arrays(cls, mass, k, delta0=0.0, *, diameter=theory.PAPER_DIAMETER,
                    section=0, params: dict | None = None, exponent: float = 1.5) -> Chain:
        """Chain from arbitrary per-grain / per-contact arrays (tapered, random, dimer).

        Parameters
        ----------
        mass : (N,) array
            Grain masses, kg.
        k : (N+1,) array
            Contact constants, N/m^n for the law F = k δⁿ (N/m^{3/2} for Hertz; 0 at
            a free end).
        delta0 : float or (N+1,) array
            Static overlaps, m.  A scalar is the overlap of contact 1 (or 0) and the
            others follow from force equilibrium δ_j = (F0/k_j)^{1/n} (below Eq. 9).
        diameter : float or (N,) array
            Grain diameters, m.
        section : int or (N,) array
            Section index per grain.
        params : dict, optional
            Metadata to store.
        exponent : float
            Exponent n of the contact law F = k δ^n the static overlaps balance (3/2:
            Hertz; :mod:`theory.laws`); recorded in ``params``.
        """
        mass = np.asarray(mass, dtype=float)
        if mass.ndim != 1 or mass.size < 2:
            raise ValueError(f"a chain needs N >= 2 grains (got mass of shape {mass.shape})")
        k = check_array("k", k, mass.size + 1, nonneg=True)
        if np.ndim(delta0) == 0:
            d0 = float(delta0)
            if not math.isfinite(d0) or d0 < 0:
                raise ValueError(f"delta0 must be finite and >= 0 (got {delta0!r})")
            delta0 = _equilibrium(k, d0, reference=1, exponent=exponent)
        p = {"kind": "arrays"} if params is None else dict(params)
        if exponent != 1.5:
            p["exponent"] = float(exponent)
        return cls(mass, k, delta0, diameter, section, p)

    @classmethod
    def from_sections(cls, sections: Sequence[Section], *, delta0: float | None = None,
                      wall_force: float | None = None, left_wall: WallKind = "paper",
                      right_wall: WallKind = "paper", exponent: float = 1.5,
                      gravity: float = 0.0) -> Chain:
        r"""Chain built from consecutive sections (paper Section 2, Fig. 1).

        Grain–grain contacts use the physical two-sphere Hertz constant
        k = (4/3) E* √R* (Johnson 1985, Eq. 4.22; :func:`theory.hertz_constant`), which
        for equal diameters at an interface is the harmonic mean of the two sections'
        k_n.  A wall contact is ``"paper"`` (the grain–grain constant of the adjacent
        grain, as the paper's Section 2 does), ``"hertz"`` (sphere on a rigid flat,
        :func:`theory.hertz_constant_wall`) or ``None`` (free end).  Sections may vary
        their grains (:class:`Tapered`, :class:`Periodic`, :class:`Disorder`).

        Static forces from force equilibrium (paper, below Eq. 9): one force F0 through
        the chain, δ0_j = (F0/k_j)^{1/n}; with ``gravity`` g the chain is vertical,
        grain 0 on top, and contact j carries the weight of the grains above it,
        :math:`F_j = F_0 + g\sum_{i<j} m_i` (F0 the force on the top wall), so the
        precompression grows with depth (Sinkovits & Sen, Phys. Rev. Lett. 74 (1995)
        2686; Hong, Ji & Kim, Phys. Rev. Lett. 82 (1999) 3058).

        Parameters
        ----------
        sections : sequence of Section
            The sections from left (top) to right (bottom).
        delta0 : float, optional
            Static overlap of the left section's grain–grain contacts δ0^L, m (>= 0);
            not with gravity.
        wall_force : float, optional
            Alternatively the static force F0, N (>= 0): with gravity, the force on the
            top wall (0 for a free top).  Default: δ0 = 0.
        left_wall, right_wall : {"paper", "hertz", "flat"}, Material or None
            Kind of wall contact (:data:`WallKind`; with gravity the right wall is the
            floor: required).
        exponent : float
            Exponent n of the contact law whose static forces k δ0^n balance (3/2: Hertz,
            the paper's; the constants k are Hertz's in any case).
        gravity : float
            Acceleration of gravity along the chain, from grain 0 to grain N-1, m/s²
            (>= 0; 9.81 for a vertical chain standing on its right wall).
        """
        sections = list(sections)
        if not sections or not all(isinstance(s, Section) for s in sections):
            raise ValueError("sections must be a non-empty sequence of Section")
        n = sum(int(s.n) for s in sections)
        if n < 2:
            raise ValueError(f"a chain needs N >= 2 grains (got {n})")
        g = float(theory._validate.check_nonnegative("gravity", gravity))
        mass = np.concatenate([np.full(s.n, s.mass) for s in sections])
        diam = np.concatenate([np.full(s.n, float(s.diameter)) for s in sections])
        sec = np.concatenate([np.full(s.n, i) for i, s in enumerate(sections)])
        # per-grain data where a section varies its grains (uniform sections keep the
        # scalar arithmetic above: the paper's chains are bitwise unchanged)
        grains = [s.grains() for s in sections]
        mats = [m for gr in grains for m in gr[1]]
        fk = np.concatenate([gr[3] for gr in grains])
        i = 0
        for s, (d, m, fm, _) in zip(sections, grains, strict=True):
            if not s.uniform:
                diam[i:i + s.n] = d
                rho = np.array([x.density for x in m])
                mass[i:i + s.n] = theory.grain_mass(d, rho) * fm
            i += s.n
        k = np.empty(n + 1)
        k[0] = _wall_k(left_wall, "left", diam[0], mats[0])
        k[-1] = _wall_k(right_wall, "right", diam[-1], mats[-1])
        i = 0
        for a, s in enumerate(sections):
            if s.uniform:
                k[i + 1:i + s.n] = s.kn
            else:
                k[i + 1:i + s.n] = _pair_k(diam[i:i + s.n - 1], mats[i:i + s.n - 1],
                                           diam[i + 1:i + s.n], mats[i + 1:i + s.n])
                k[i + 1:i + s.n] *= fk[i + 1:i + s.n]
            i += s.n
            if a + 1 < len(sections):
                t = sections[a + 1]
                if s.uniform and t.uniform:
                    k[i] = float(theory.hertz_constant(s.diameter, s.material, t.diameter,
                                                       t.material))
                else:
                    k[i] = float(_pair_k(diam[i - 1:i], mats[i - 1:i], diam[i:i + 1],
                                         mats[i:i + 1])[0]) * fk[i]
        if delta0 is not None and wall_force is not None:
            raise ValueError("give at most one of delta0 (m) or wall_force (N)")
        ref = 1 if sections[0].n > 1 else 0
        if g > 0:
            if delta0 is not None:
                raise ValueError("with gravity give wall_force (the force on the top wall, N; "
                                 "0 for a free top), not delta0: the overlaps grow with depth")
            if k[-1] == 0:
                raise ValueError("gravity needs a floor: right_wall must not be None")
            f = 0.0 if wall_force is None else float(
                theory._validate.check_nonnegative("wall_force", wall_force))
            if f > 0 and k[0] == 0:
                raise ValueError("a top wall force needs a top wall (left_wall)")
            d0 = _gravity_overlaps(k, mass, f, g, exponent)
        elif wall_force is not None:
            f = float(theory._validate.check_nonnegative("wall_force", wall_force))
            d0 = _equilibrium(k, (f / k[ref]) ** (1 / exponent), reference=ref,
                              exponent=exponent)
        else:
            dl = 0.0 if delta0 is None else delta0
            dl = float(theory._validate.check_nonnegative("delta0", dl))
            d0 = _equilibrium(k, dl, reference=ref, exponent=exponent)
        params = {
            "kind": "sections",
            "sections": [s.to_dict() for s in sections],
            "delta0": float(d0[ref]),
            "left_wall": _wall_param(left_wall),
            "right_wall": _wall_param(right_wall),
        }
        if exponent != 1.5:
            params["exponent"] = float(exponent)
        if g > 0:
            params["gravity"] = g
        return cls(mass, k, d0, diam, sec, params)

    @classmethod
    def from_sections_seeds(cls, sections: Sequence[Section], seeds: Sequence[int], *,
                            section: int | None = None, **kwargs) -> list[Chain]:
        """The chains of :meth:`from_sections` for many seeds of one section's disorder.

        Chain q is, bit for bit, ``from_sections(sections', **kwargs)`` with
        ``sections'`` the sections in which section ``section``'s
        :class:`Disorder` has the seed ``seeds[q]``.  Where the disorder leaves the
        diameters alone (``Disorder.diameter == 0``) and there is no gravity, the
        sections' geometry — diameters, nominal masses, two-sphere and wall Hertz
        constants — is built once and each seed only draws its factors: masses
        m_i = m⁰_i f^m_i and grain–grain constants k_j = k⁰_j f^k_j (:class:`Disorder`),
        then the static overlaps of force equilibrium (paper, below Eq. 9).  Otherwise
        each chain is built by :meth:`from_sections`.

        Parameters
        ----------
        sections : sequence of Section
            As for :meth:`from_sections`.
        seeds : sequence of int
            The seeds, one chain each.
        section : int, optional
            Index of the section whose disorder takes the seeds (default: the only
            section with a disorder).
        **kwargs
            The keywords of :meth:`from_sections` (``delta0``, ``wall_force``, walls,
            ``exponent``, ``gravity``).

        Returns
        -------
        list of Chain
        """
        sections = list(sections)
        if not sections or not all(isinstance(x, Section) for x in sections):
            raise ValueError("sections must be a non-empty sequence of Section")
        disordered = [i for i, x in enumerate(sections) if x.disorder is not None]
        if section is None:
            if len(disordered) != 1:
                raise ValueError("section must name the section whose disorder takes the "
                                 f"seeds (sections with a disorder: {disordered})")
            section = disordered[0]
        if section not in disordered:
            raise ValueError(f"section must be the index of a section with a Disorder, "
                             f"one of {disordered} (got {section!r})")
        seeds = [int(x) for x in seeds]
        dis = sections[section].disorder

        def with_seed(seed: int) -> list[Section]:
            out = list(sections)
            out[section] = Section(sections[section].n, sections[section].diameter,
                                   sections[section].material, sections[section].profile,
                                   Disorder(dis.mass, dis.stiffness, dis.diameter, seed))
            return out

        if dis.diameter != 0 or float(kwargs.get("gravity", 0.0)) != 0:
            return [cls.from_sections(with_seed(x), **kwargs) for x in seeds]
        # the geometry once: the same sections with unit factors (1 + 0·√3 U = 1
        # exactly, and x·1 = x), so every product below is from_sections' own
        nominal = list(sections)
        nominal[section] = Section(sections[section].n, sections[section].diameter,
                                   sections[section].material, sections[section].profile,
                                   Disorder(0.0, 0.0, 0.0, dis.seed))
        base = cls.from_sections(nominal, **kwargs)
        lo = sum(int(x.n) for x in sections[:section])
        n_sec = int(sections[section].n)
        exponent = float(kwargs.get("exponent", 1.5))
        ref = 1 if sections[0].n > 1 else 0
        delta0, wall_force = kwargs.get("delta0"), kwargs.get("wall_force")
        out = []
        for seed in seeds:
            d = Disorder(dis.mass, dis.stiffness, 0.0, seed)
            f = d.factors(n_sec)
            mass = np.array(base.mass)
            mass[lo:lo + n_sec] = mass[lo:lo + n_sec] * f["mass"]
            k = np.array(base.k)
            first = lo if lo > 0 else lo + 1  # the contact left of the section's grain 0
            k[first:lo + n_sec] = k[first:lo + n_sec] * f["stiffness"][first - lo:]
            if wall_force is not None:
                fw = float(wall_force)
                d0 = _equilibrium(k, (fw / k[ref]) ** (1 / exponent), reference=ref,
                                  exponent=exponent)
            else:
                d0 = _equilibrium(k, 0.0 if delta0 is None else float(delta0),
                                  reference=ref, exponent=exponent)
            params = dict(base.params)
            params["sections"] = [x.to_dict() for x in with_seed(seed)]
            params["delta0"] = float(d0[ref])
            out.append(cls(mass, k, d0, base.diameter, base.section, params))
        return out

    @classmethod
    def two_section(cls, n_left: int, n_right: int, alpha_rho: float = 1.0,
                    alpha_kn: float = 1.0, delta0_over_d: float = 0.0, *,
                    material: Material = theory.PAPER_MATERIAL,
                    diameter: float = theory.PAPER_DIAMETER, left_wall: WallKind = "paper",
                    right_wall: WallKind = "paper") -> Chain:
        """The paper's two-section chain (Section 2, Fig. 1).

        The right section is ``material.scaled(alpha_rho, alpha_kn)``: density × α_ρ,
        k_n × α_kn.  δ0^L = ``delta0_over_d`` × d, and δ0^R = α_kn^{-2/3} δ0^L from force
        equilibrium.  ``n_right = 0`` gives a monodisperse chain.
        """
        if not isinstance(n_left, int | np.integer) or n_left < 1:
            raise ValueError(f"n_left must be an integer >= 1 (got {n_left!r})")
        if not isinstance(n_right, int | np.integer) or n_right < 0:
            raise ValueError(f"n_right must be an integer >= 0 (got {n_right!r})")
        x = float(theory._validate.check_nonnegative("delta0_over_d", delta0_over_d))
        d = _positive_scalar("diameter", diameter)
        secs = [Section(int(n_left), d, material)]
        if n_right:
            secs.append(Section(int(n_right), d, material.scaled(alpha_rho, alpha_kn)))
        ch = cls.from_sections(secs, delta0=x * d, left_wall=left_wall, right_wall=right_wall)
        ch.params.update({"kind": "two_section", "n_left": int(n_left),
                          "n_right": int(n_right), "alpha_rho": float(alpha_rho),
                          "alpha_kn": float(alpha_kn), "delta0_over_d": x})
        return ch

    def medium(self, law: theory.ContactLaw | None = None, drag: float = 0.0):
        """The chain's coefficients as a :class:`theory.medium.Medium` (the continuum's input).

        Masses, contact constants, static overlaps, diameters, gravity and the periodic
        sections (:class:`Periodic` profiles: start, stop, cell length) with the contact
        ``law`` (default Hertz) and on-site drag rate ``drag`` (1/s) of the run.
        ValueError if the law's exponent is not the one the static overlaps balance.
        """
        from theory.medium import Medium

        law = theory.as_law(law)
        if law.exponent != self.exponent and np.any(self.delta0 > 0):
            raise ValueError(f"law exponent {law.exponent:g} differs from the exponent "
                             f"{self.exponent:g} the chain's static overlaps balance")
        specs = self.params.get("sections", [])
        cells = []
        for sl in self.section_slices():
            a = int(self.section[sl.start])
            prof = (specs[a].get("profile") or {}) if a < len(specs) else {}
            if prof.get("profile") == "periodic":
                cells.append((sl.start, sl.stop, len(prof["cell"])))
        return Medium(self.mass, self.k, self.delta0, self.diameter, law=law, drag=drag,
                      gravity=self.gravity, cells=tuple(cells), info=dict(self.params))

    def with_params(self, **extra) -> Chain:
        """Copy with ``params`` updated by ``extra``."""
        return Chain(self.mass, self.k, self.delta0, self.diameter, self.section,
                     {**self.params, **extra})

    def __repr__(self) -> str:
        return (f"Chain(n={self.n}, mass=[{self.mass.min():.4g}, {self.mass.max():.4g}] kg, "
                f"delta0_max={self.delta0.max():.4g} m, params={self.params.get('kind')})")


def _equilibrium(k: np.ndarray, delta0: float, *, reference: int,
                 exponent: float = 1.5) -> np.ndarray:
    """Static overlaps (F0/k_j)^{1/n} of the present contacts (below Eq. 9); 0 elsewhere."""
    out = np.zeros_like(k)
    if delta0 == 0:
        return out
    if k[reference] == 0:
        raise ValueError("the reference contact of delta0 is absent (k = 0)")
    n = float(exponent)
    if not (math.isfinite(n) and n >= 1):
        raise ValueError(f"exponent must be >= 1 (got {exponent!r})")
    present = k > 0
    f0 = float(k[reference]) * delta0**n
    if n == 1.5:
        out[present] = theory.static_overlaps(k[present], force=f0)
    else:
        out[present] = (f0 / k[present]) ** (1.0 / n)
    out[k == k[reference]] = delta0  # exactly δ0 (not δ0 ± 1 ulp) where k is the same
    return out
