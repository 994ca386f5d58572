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
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._validate import check_positive, check_range

__all__ = [
    "Material",
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
