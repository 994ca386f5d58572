r"""Materials, grain masses and Hertz contact constants.

The contact law of the paper (Eq. 1) is :math:`F = k_n [\delta]_+^{3/2}` with
:math:`\delta` the overlap of two touching spheres.

Hertz theory (Johnson, *Contact Mechanics*, 1985, Eq. 4.22) gives for two elastic
spheres of radii :math:`R_1, R_2`, Young's moduli :math:`E_1, E_2` and Poisson ratios
:math:`\nu_1, \nu_2`

.. math::
    F = \tfrac{4}{3} E^* \sqrt{R^*}\, \delta^{3/2}, \qquad
    \frac{1}{E^*} = \frac{1-\nu_1^2}{E_1} + \frac{1-\nu_2^2}{E_2}, \qquad
    \frac{1}{R^*} = \frac{1}{R_1} + \frac{1}{R_2}.

For two identical spheres of diameter :math:`d` this is
:math:`k = E d^{1/2} / (3(1-\nu^2))`.  The paper prints
:math:`k_n = 2E d^{1/2}/(3(1-\nu^2))`, twice the Hertz value (docs/physics.md §1).  The
paper's figures (v̄max/v0 = 0.0822 at δ0/d = 1e-3, Table 2) are reproduced by the
*Hertz* constant with ν = 0.30, not by the printed formula with ν = 0.25 of its
Table 1; both conventions are available here (:func:`hertz_constant` and
:func:`paper_kn`), and :data:`PAPER_MATERIAL` records the choice that reproduces the
paper.

Units: density ρ in kg/m³, Young's modulus E in Pa, the Poisson ratio ν dimensionless,
diameters in m, Hertz constants in N/m^{3/2}.

Material library
----------------
:data:`MATERIALS` names the materials of granular-chain experiments, each with its
source (:class:`LibraryMaterial`); :func:`get_material` looks one up by name or alias
(``"steel"`` is stainless steel 316, the grade of the paper's Table 1 and of Daraio et
al. 2006).  Values are room-temperature handbook or literature values for bulk
material; a real batch of beads differs by a few per cent (E of polymers by more: it
depends on moisture, temperature and strain rate), so an experiment should use its own
measured values (a table ``{density, youngs_modulus, poisson_ratio}`` in a scenario).
For equal diameters only the ratios matter for the interface (paper Section 2):
α_ρ = ρ_R/ρ_L and α_kn = k_R/k_L = [E/(1-ν²)]_R / [E/(1-ν²)]_L
(:func:`material_ratios`, from :func:`hertz_constant`).
"""

from __future__ import annotations

import difflib
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from ._validate import check_positive, check_range

__all__ = [
    "Material",
    "LibraryMaterial",
    "MATERIALS",
    "get_material",
    "material_names",
    "material_ratios",
    "resolve_material_name",
    "STEEL_TABLE1",
    "PAPER_MATERIAL",
    "PAPER_DIAMETER",
    "grain_mass",
    "effective_modulus",
    "hertz_constant",
    "hertz_constant_wall",
    "paper_kn",
    "hertz_kn_identical",
]

PAPER_DIAMETER: float = 5e-3
"""Grain diameter of the paper, m (Table 1)."""


@dataclass(frozen=True)
class Material:
    """An isotropic elastic material.

    Parameters
    ----------
    density : float
        Mass density ρ, kg/m³ (> 0).
    youngs_modulus : float
        Young's modulus E, Pa (> 0).
    poisson_ratio : float
        Poisson ratio ν, dimensionless, in (-1, 0.5).
    name : str, optional
        Free label.
    """

    density: float
    youngs_modulus: float
    poisson_ratio: float
    name: str = ""

    def __post_init__(self) -> None:
        check_positive("density", self.density)
        check_positive("youngs_modulus", self.youngs_modulus)
        check_range("poisson_ratio", self.poisson_ratio, -1.0, 0.5)

    @property
    def contact_modulus(self) -> float:
        """Plane-strain modulus E/(1-ν²), Pa."""
        return self.youngs_modulus / (1.0 - self.poisson_ratio**2)

    def scaled(self, alpha_rho: float = 1.0, alpha_kn: float = 1.0) -> Material:
        """Return a material with density × ``alpha_rho`` and contact stiffness × ``alpha_kn``.

        The paper specifies the right section by the ratios α_ρ = ρ^R/ρ^L and
        α_kn = k_n^R/k_n^L (Section 2).  For equal diameters k_n ∝ E/(1-ν²), so
        scaling E by α_kn at fixed ν scales k_n by α_kn exactly.
        """
        check_positive("alpha_rho", alpha_rho)
        check_positive("alpha_kn", alpha_kn)
        return Material(
            density=self.density * alpha_rho,
            youngs_modulus=self.youngs_modulus * alpha_kn,
            poisson_ratio=self.poisson_ratio,
            name=f"{self.name}(alpha_rho={alpha_rho:g}, alpha_kn={alpha_kn:g})",
        )


STEEL_TABLE1 = Material(7900.0, 193e9, 0.25, name="stainless steel (paper Table 1)")
"""The paper's Table 1 material: ρ = 7.9 g/cm³, E = 193 GPa, ν = 0.25."""

PAPER_MATERIAL = Material(7900.0, 193e9, 0.30, name="stainless steel, nu=0.30 (reproduces paper)")
"""The material that reproduces the paper's numbers with the Hertz constant.

docs/physics.md §1: only k_n/m matters; v̄max/v0 = 0.0822 at δ0/d = 1e-3 and Table 2 are
reproduced by the physical Hertz constant with ν = 0.30 (not Table 1's 0.25, not the
paper's printed k_n).  The paper scenarios use this material and say why.
"""


@dataclass(frozen=True)
class LibraryMaterial:
    """A named material of :data:`MATERIALS`: its values and where they come from.

    Parameters
    ----------
    key : str
        The name used in scenarios and on the command line (``material = "brass"``).
    material : Material
        ρ (kg/m³), E (Pa), ν.
    source : str
        The reference of the three values.
    aliases : tuple of str
        Other accepted names.
    """

    key: str
    material: Material
    source: str
    aliases: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        """Plain values with units in the keys' docs: name, ρ (kg/m³), E (Pa), ν, source."""
        m = self.material
        return {"name": self.key, "aliases": list(self.aliases), "description": m.name,
                "density": m.density, "youngs_modulus": m.youngs_modulus,
                "poisson_ratio": m.poisson_ratio, "source": self.source}


def _entry(key: str, description: str, density: float, youngs_modulus: float,
           poisson_ratio: float, source: str, aliases: tuple[str, ...] = ()
           ) -> LibraryMaterial:
    return LibraryMaterial(key, Material(density, youngs_modulus, poisson_ratio,
                                         name=description), source, aliases)


_LIBRARY = (
    LibraryMaterial("paper", PAPER_MATERIAL,
                    "the paper's Table 1 (ρ = 7.9 g/cm³, E = 193 GPa) with ν = 0.30, the "
                    "value that reproduces its figures with the Hertz constant "
                    "(docs/physics.md §1)"),
    LibraryMaterial("table1", STEEL_TABLE1, "the paper's Table 1 as printed (ν = 0.25)"),
    _entry("stainless_steel_316", "stainless steel AISI 316", 8000.0, 193e9, 0.30,
           "Daraio, Nesterenko, Herbold & Jin, Phys. Rev. E 73, 026610 (2006) (type 316 "
           "beads); the same E as the paper's Table 1",
           aliases=("steel", "stainless_steel", "316")),
    _entry("chrome_steel_52100", "chrome (bearing) steel AISI 52100", 7830.0, 203e9, 0.30,
           "AISI 52100 / ASTM A295 bearing-ball specification: E = 29.5e6 psi (203 GPa), "
           "ρ = 0.283 lb/in³ (7830 kg/m³); ν = 0.27-0.30 quoted for 52100 (0.30 taken)",
           aliases=("chrome_steel", "52100", "bearing_steel")),
    _entry("brass", "brass (cartridge brass, C26000, 70Cu-30Zn)", 8530.0, 110e9, 0.375,
           "ASM Handbook Vol. 2 (1990), C26000 cartridge brass: ρ = 8.53 g/cm³, "
           "E = 110 GPa, ν = 0.375",
           aliases=("c26000",)),
    _entry("aluminium_6061", "aluminium alloy 6061-T6", 2700.0, 68.9e9, 0.33,
           "ASM Handbook Vol. 2 (1990), 6061-T6: ρ = 2.70 g/cm³, E = 68.9 GPa, ν = 0.33",
           aliases=("aluminum_6061", "aluminium", "aluminum", "6061")),
    _entry("ptfe", "polytetrafluoroethylene (PTFE, Teflon)", 2200.0, 1.46e9, 0.46,
           "Daraio, Nesterenko, Herbold & Jin, Phys. Rev. E 72, 016603 (2005) and "
           "Phys. Rev. E 73, 026610 (2006) (PTFE beads)",
           aliases=("teflon",)),
    _entry("soda_lime_glass", "soda-lime-silica glass", 2500.0, 70e9, 0.20,
           "EN 572-1 (soda lime silicate glass): ρ = 2500 kg/m³, E = 70 GPa, ν = 0.2 "
           "(0.22-0.24 measured on float glass)",
           aliases=("glass", "soda_lime")),
    _entry("tungsten_carbide", "tungsten carbide (WC)", 15000.0, 630e9, 0.24,
           "Martienssen & Warlimont (eds.), Springer Handbook of Condensed Matter and "
           "Materials Data (2005), WC: ρ = 15 g/cm³, E = 630 GPa, ν = 0.24 (cemented WC-Co "
           "balls: 5-10 % lower E)",
           aliases=("wc", "carbide")),
    _entry("nylon_66", "nylon 6/6 (polyamide 66, dry)", 1140.0, 2.9e9, 0.41,
           "Ashby, Materials and the Environment (2nd ed., 2013), polyamides: "
           "ρ = 1120-1140 kg/m³, E = 2.62-3.2 GPa (the mid value; moisture lowers E to "
           "~1.5-1.8 GPa); ν = 0.41 (dry PA66, typical)",
           aliases=("nylon", "pa66", "polyamide")),
)

MATERIALS: Mapping[str, LibraryMaterial] = MappingProxyType({m.key: m for m in _LIBRARY})
"""The named materials, by key (``hertzchain materials`` prints them): ρ in kg/m³, E in
Pa, ν, and a source for every value."""

_ALIASES = {a: m.key for m in _LIBRARY for a in (m.key, *m.aliases)}


def material_names() -> tuple[str, ...]:
    """Every accepted material name: the keys of :data:`MATERIALS` and their aliases."""
    return tuple(_ALIASES)


def resolve_material_name(name: str) -> str:
    """The key of :data:`MATERIALS` for ``name`` (case and ``-``/space insensitive).

    Raises
    ------
    ValueError
        Naming the unknown name, the closest known ones (did you mean) and the keys.
    """
    if not isinstance(name, str):
        raise ValueError(f"a material name must be a string (got {name!r})")
    norm = name.strip().lower().replace("-", "_").replace(" ", "_")
    if norm in _ALIASES:
        return _ALIASES[norm]
    close = difflib.get_close_matches(norm, list(_ALIASES), n=3, cutoff=0.6)
    hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
    raise ValueError(f"unknown material {name!r}{hint} (known: {', '.join(MATERIALS)}; "
                     "`hertzchain materials` lists their values and sources)")


def get_material(name: str) -> Material:
    """The :class:`Material` called ``name`` in :data:`MATERIALS` (or an alias).

    Raises
    ------
    ValueError
        An unknown name (with the closest known names).
    """
    return MATERIALS[resolve_material_name(name)].material


def material_ratios(left: Material, right: Material) -> tuple[float, float]:
    r"""The paper's (α_ρ, α_kn) of an interface between two materials, equal diameters.

    α_ρ = ρ_R/ρ_L and α_kn = k_R/k_L with k the identical-pair Hertz constant
    E d^{1/2}/(3(1-ν²)) (:func:`hertz_constant`; Johnson 1985, Eq. 4.22), so that
    α_kn = [E/(1-ν²)]_R / [E/(1-ν²)]_L, independent of the diameter (paper Section 2:
    the right section is specified by these two ratios).
    """
    return (right.density / left.density, right.contact_modulus / left.contact_modulus)


def grain_mass(diameter, density):
    """Mass of a sphere, m = (π/6) d³ ρ (paper Section 2), kg.

    Parameters
    ----------
    diameter : float or array
        Sphere diameter d, m (> 0).
    density : float or array
        Mass density ρ, kg/m³ (> 0).
    """
    d = check_positive("diameter", diameter)
    rho = check_positive("density", density)
    out = np.pi / 6.0 * d**3 * rho
    return out if out.ndim else float(out)


def effective_modulus(e1, nu1, e2, nu2):
    """Hertz effective modulus E* = [(1-ν1²)/E1 + (1-ν2²)/E2]⁻¹, Pa (Johnson 1985, Eq. 4.22).

    ``e2 = np.inf`` is a rigid body.
    """
    e1 = check_positive("youngs_modulus", e1)
    e2 = np.asarray(e2, dtype=float)
    if np.any(np.isnan(e2)) or np.any(e2 <= 0):
        raise ValueError("youngs_modulus of the second body must be > 0 (inf = rigid)")
    nu1 = check_range("poisson_ratio", nu1, -1.0, 0.5)
    nu2 = check_range("poisson_ratio", nu2, -1.0, 0.5)
    rigid = np.isinf(e2)
    inv = (1 - nu1**2) / e1 + np.where(rigid, 0.0, (1 - nu2**2) / np.where(rigid, 1.0, e2))
    out = 1.0 / inv
    return out if out.ndim else float(out)


def hertz_constant(d1, mat1: Material, d2=None, mat2: Material | None = None):
    r"""Physical Hertz constant k of two spheres, F = k δ^{3/2}; units N/m^{3/2}.

    .. math:: k = \tfrac{4}{3} E^* \sqrt{R^*}

    (Johnson 1985, Eq. 4.22; docs/physics.md §1).  For identical spheres of diameter d,
    k = E d^{1/2}/(3(1-ν²)).  For equal diameters and different materials it is the
    harmonic mean of the two identical-pair constants, 2 k1 k2/(k1 + k2).

    Parameters
    ----------
    d1 : float or array
        Diameter of the first sphere, m.
    mat1 : Material
        Material of the first sphere.
    d2 : float or array, optional
        Diameter of the second sphere, m (default ``d1``).
    mat2 : Material, optional
        Material of the second sphere (default ``mat1``).
    """
    d2 = d1 if d2 is None else d2
    mat2 = mat1 if mat2 is None else mat2
    d1 = check_positive("d1", d1)
    d2 = check_positive("d2", d2)
    r1, r2 = d1 / 2, d2 / 2
    r_eff = r1 * r2 / (r1 + r2)
    e_eff = effective_modulus(
        mat1.youngs_modulus, mat1.poisson_ratio, mat2.youngs_modulus, mat2.poisson_ratio
    )
    out = 4.0 / 3.0 * e_eff * np.sqrt(r_eff)
    return out if np.ndim(out) else float(out)


def hertz_constant_wall(d, mat: Material, wall: Material | None = None):
    r"""Hertz constant of a sphere against a flat wall, N/m^{3/2}.

    A flat wall has R → ∞, so R* = d/2; ``wall=None`` is a rigid wall (E → ∞):
    k = (4/3) E/(1-ν²) (d/2)^{1/2} (Johnson 1985, Eq. 4.22).  The paper instead treats
    the wall contact "as the grain–grain interaction" (Section 2); the discrete solver
    offers both.
    """
    d = check_positive("d", d)
    if wall is None:
        e_eff = mat.contact_modulus
    else:
        e_eff = effective_modulus(
            mat.youngs_modulus, mat.poisson_ratio, wall.youngs_modulus, wall.poisson_ratio
        )
    out = 4.0 / 3.0 * e_eff * np.sqrt(d / 2)
    return out if np.ndim(out) else float(out)


def hertz_kn_identical(d, mat: Material):
    """Hertz constant of two identical spheres, k = E d^{1/2}/(3(1-ν²)), N/m^{3/2}."""
    return hertz_constant(d, mat)


def paper_kn(d, mat: Material):
    r"""The paper's printed elastic coefficient k_n = 2E d^{1/2}/(3(1-ν²)), N/m^{3/2}.

    Paper Section 2, below Eq. 1.  This is **twice** the Hertz value for two identical
    spheres (see :func:`hertz_constant` and docs/physics.md §1); it is kept as an explicit
    alternative so the paper's convention can be examined, but it does not reproduce
    the paper's own figures (v̄max/v0 at δ0/d = 1e-3 comes out ≈ 0.041, not 0.0822).
    """
    d = check_positive("d", d)
    out = 2.0 * mat.youngs_modulus / (3.0 * (1.0 - mat.poisson_ratio**2)) * np.sqrt(d)
    return out if np.ndim(out) else float(out)
