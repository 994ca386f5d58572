"""Tests of the continuum medium: coefficients, equilibrium, staggered discretisation."""

import numpy as np
import pytest

import theory
from continuum import Medium

D = theory.PAPER_DIAMETER


def test_two_section_matches_paper_setup():
    ar, ak = 0.5, 2.0
    med = Medium.two_section(10, 5, 1e-3 * D, ar, ak)
    right = theory.PAPER_MATERIAL.scaled(ar, ak)
    assert med.mass[0] == pytest.approx(theory.grain_mass(D, 7900.0))
    assert med.mass[-1] == pytest.approx(ar * med.mass[0])
    k_l = theory.hertz_constant(D, theory.PAPER_MATERIAL)
    assert med.k[1] == pytest.approx(k_l)
    assert med.k[-1] == pytest.approx(ak * k_l)
    # interface contact (grains 9 and 10): harmonic mean of the two sections
    assert med.k[10] == pytest.approx(2 * k_l * ak * k_l / (k_l + ak * k_l))
    assert med.k[10] == pytest.approx(theory.hertz_constant(D, theory.PAPER_MATERIAL, D, right))
    # force equilibrium k δ0^{3/2} = F0 (paper below Eq. 9)
    f = med.k * med.delta0**1.5
    assert np.ptp(f) < 1e-12 * f.max()
    assert med.delta0[0] == pytest.approx(1e-3 * D)
    assert med.delta0[-1] == pytest.approx(1e-3 * D * ak ** (-2 / 3))


@pytest.mark.parametrize("n", [1, 3, 5, 9])
def test_discretisation_preserves_mass_and_compliance(n):
    med = Medium.two_section(6, 4, 1e-3 * D, 5.0, 0.2)
    disc = med.discretise(n)
    # a node on every grain centre, a face on every contact
    assert np.allclose(disc.x_nodes[disc.grain_nodes], np.arange(med.n_grains))
    assert np.allclose(disc.x_faces[disc.contact_faces], np.arange(med.n_grains + 1) - 0.5)
    # total mass and the compliance between the first and last grain centre are exact
    assert disc.h * disc.mass.sum() == pytest.approx(med.mass.sum(), rel=1e-14)
    inner = (disc.x_faces > 0) & (disc.x_faces < med.n_grains - 1)
    assert np.sum(disc.h / disc.stiffness[inner]) == pytest.approx(
        np.sum(1.0 / (1.5 * med.k[1:-1] * np.sqrt(med.delta0[1:-1]))), rel=1e-12)
    assert np.allclose(disc.k * disc.delta0**1.5, med.force0, rtol=1e-12)


def test_bad_inputs_raise():
    with pytest.raises(ValueError, match="odd"):
        Medium.uniform(5, 1e-6).discretise(4)
    with pytest.raises(ValueError, match="N\\+1"):
        Medium(mass=np.ones(3), k=np.ones(3), delta0=np.zeros(3))
    with pytest.raises(ValueError, match="equilibrium"):
        Medium(mass=np.ones(2), k=np.array([1.0, 2.0, 1.0]), delta0=np.full(3, 1e-6))
    with pytest.raises(ValueError, match="n_left"):
        Medium.two_section(0, 3, 1e-6)


def test_from_grain_arrays_scalar_delta0():
    k = np.array([2.0, 1.0, 1.0, 3.0]) * 1e9
    med = Medium.from_grain_arrays(np.full(3, 1e-3), k, 1e-6)
    assert med.delta0[1] == pytest.approx(1e-6)
    assert np.allclose(med.k * med.delta0**1.5, med.force0)
