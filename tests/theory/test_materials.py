"""Hertz constants, masses and precompression (paper Eq. 1, Section 2; docs/physics.md §1)."""

import numpy as np
import pytest

import theory
from theory import Material


def test_hertz_constant_hand_calculation():
    # Hand calculation for two identical steel spheres, d = 5 mm, nu = 0.3:
    # E* = E / (2 (1 - nu^2)), R* = d/4, k = 4/3 E* sqrt(R*).
    E, nu, d = 193e9, 0.3, 5e-3
    e_star = E / (2 * (1 - nu**2))
    k_hand = 4.0 / 3.0 * e_star * np.sqrt(d / 4)
    k = theory.hertz_constant(d, Material(7900, E, nu))
    assert k == pytest.approx(k_hand, rel=1e-14)
    # and the closed form E d^{1/2} / (3 (1 - nu^2)) of docs/physics.md §1
    assert k == pytest.approx(E * np.sqrt(d) / (3 * (1 - nu**2)), rel=1e-14)


def test_paper_kn_is_twice_hertz():
    # docs/physics.md §1: the paper's printed k_n = 2E d^{1/2}/(3(1-nu^2)) is 2x the Hertz value.
    for mat in (theory.STEEL_TABLE1, theory.PAPER_MATERIAL, Material(2200, 1.5e9, 0.46)):
        ratio = theory.paper_kn(5e-3, mat) / theory.hertz_constant(5e-3, mat)
        assert ratio == pytest.approx(2.0, rel=1e-14)


def test_paper_reproducing_choice_kn_over_m():
    # Only k_n/m matters.  The choice that reproduces the paper (Hertz, nu = 0.30)
    # differs from the Table-1 printed formula (nu = 0.25) by the factor
    # 2 (1 - 0.30^2)/(1 - 0.25^2) ~ 1.94, not by a rounding.
    k_paper = theory.paper_kn(5e-3, theory.STEEL_TABLE1)
    k_used = theory.hertz_constant(5e-3, theory.PAPER_MATERIAL)
    assert k_paper / k_used == pytest.approx(2 * (1 - 0.09) / (1 - 0.0625), rel=1e-14)


def test_harmonic_mean_rule_for_equal_diameters(rng):
    # For equal diameters, the two-material Hertz constant is the harmonic mean of the
    # two identical-pair constants (docs/physics.md §1: the interface contact of a composite chain).
    for _ in range(20):
        m1 = Material(rng.uniform(1e3, 1e4), rng.uniform(1e9, 4e11), rng.uniform(-0.9, 0.49))
        m2 = Material(rng.uniform(1e3, 1e4), rng.uniform(1e9, 4e11), rng.uniform(-0.9, 0.49))
        d = rng.uniform(1e-3, 2e-2)
        k1, k2 = theory.hertz_constant(d, m1), theory.hertz_constant(d, m2)
        k12 = theory.hertz_constant(d, m1, d, m2)
        assert k12 == pytest.approx(2 * k1 * k2 / (k1 + k2), rel=1e-13)


def test_hertz_unequal_radii_and_wall():
    mat = theory.PAPER_MATERIAL
    d1, d2 = 4e-3, 6e-3
    r_eff = (d1 / 2) * (d2 / 2) / (d1 / 2 + d2 / 2)
    expect = 4 / 3 * mat.contact_modulus / 2 * np.sqrt(r_eff)
    assert theory.hertz_constant(d1, mat, d2, mat) == pytest.approx(expect, rel=1e-14)
    # rigid flat wall: R* = R, E* = E/(1-nu^2)
    assert theory.hertz_constant_wall(d1, mat) == pytest.approx(
        4 / 3 * mat.contact_modulus * np.sqrt(d1 / 2), rel=1e-14)
    # the wall limit of the sphere formula: d2 -> inf, E2 -> inf
    big = Material(1.0, 1e30, 0.0)
    assert theory.hertz_constant(d1, mat, 1e12, big) == pytest.approx(
        theory.hertz_constant_wall(d1, mat), rel=1e-6)


def test_grain_mass():
    assert theory.grain_mass(5e-3, 7900) == pytest.approx(4 / 3 * np.pi * 2.5e-3**3 * 7900)


def test_scaled_material_scales_kn_and_density():
    mat = theory.PAPER_MATERIAL
    s = mat.scaled(alpha_rho=0.2, alpha_kn=5.0)
    assert s.density / mat.density == pytest.approx(0.2)
    assert theory.hertz_constant(5e-3, s) / theory.hertz_constant(5e-3, mat) == pytest.approx(5.0)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"density": -1.0, "youngs_modulus": 1e9, "poisson_ratio": 0.3}, "density"),
        ({"density": 1.0, "youngs_modulus": 0.0, "poisson_ratio": 0.3}, "youngs_modulus"),
        ({"density": 1.0, "youngs_modulus": 1e9, "poisson_ratio": 0.5}, "poisson_ratio"),
        ({"density": 1.0, "youngs_modulus": 1e9, "poisson_ratio": -1.0}, "poisson_ratio"),
        ({"density": float("nan"), "youngs_modulus": 1e9, "poisson_ratio": 0.3}, "density"),
    ],
)
def test_material_validation(kwargs, name):
    with pytest.raises(ValueError, match=name):
        Material(**kwargs)


def test_static_overlaps_force_equilibrium(rng):
    k = rng.uniform(1e9, 1e10, size=50)
    delta = theory.static_overlaps(k, delta0=5e-6)
    assert delta[0] == pytest.approx(5e-6, rel=1e-14)
    force = k * delta**1.5
    np.testing.assert_allclose(force, force[0], rtol=1e-13)
    # given the force instead
    np.testing.assert_allclose(theory.static_overlaps(k, force=force[0]), delta, rtol=1e-13)
    # paper below Eq. 9: delta0^R/delta0^L = alpha_kn^{-2/3}
    two = theory.static_overlaps([1.0, 5.0], delta0=1.0)
    assert two[1] == pytest.approx(5.0 ** (-2 / 3), rel=1e-14)


def test_static_overlaps_validation():
    with pytest.raises(ValueError, match="exactly one"):
        theory.static_overlaps([1.0], delta0=1.0, force=1.0)
    with pytest.raises(ValueError, match="delta0"):
        theory.static_overlaps([1.0], delta0=-1.0)
    with pytest.raises(ValueError, match="k_contacts"):
        theory.static_overlaps([1.0, -2.0], delta0=1.0)


def test_wave_contact_energy():
    # (2/5) k ([r]_+^{5/2} - delta0^{5/2}); exact for moderate waves, negative when opened
    k, d0 = 5e9, 5e-6
    r = np.array([0.0, -1e-6, 2e-6, 5e-6, 6e-6, 0.0])
    d = np.array([d0, d0, d0, d0, d0, 0.0])
    expect = 0.4 * k * (np.maximum(r, 0) ** 2.5 - d**2.5)
    np.testing.assert_allclose(theory.wave_contact_energy(r, k, d), expect, rtol=1e-13,
                               atol=1e-30)
    # a tiny wave on a large precompression: the series F0*x + (3/4)F0*x^2/delta0 ...
    # (x = r - delta0) is recovered to 1e-12, which the naive difference misses
    x = 1e-12 * d0
    series = k * d0**1.5 * x + 0.75 * k * d0**0.5 * x**2
    assert theory.wave_contact_energy(d0 + x, k, d0) == pytest.approx(series, rel=1e-9)
    naive = 0.4 * k * ((d0 + x) ** 2.5 - d0**2.5)
    assert abs(naive / series - 1) > 1e-6
