"""The shared medium (theory.medium) and its staggered discretisation (continuum.medium)."""

import numpy as np
import pytest

import discrete
import theory
from continuum import Medium, discretise
from theory.medium import EQUILIBRIUM_RTOL

from ._helpers import two_section

D = theory.PAPER_DIAMETER


def test_chain_hands_over_its_coefficients():
    """discrete.Chain.medium: the same arrays (one builder), the law, drag and gravity."""
    ch = discrete.Chain.two_section(10, 5, 0.5, 2.0, 1e-3)
    med = ch.medium(theory.PowerLaw(1.5), 3.0)
    for name in ("mass", "k", "delta0", "diameter"):
        np.testing.assert_array_equal(getattr(med, name), getattr(ch, name))
    assert med.law == theory.HERTZ and med.drag == 3.0 and med.gravity == 0.0
    np.testing.assert_allclose(med.f0, ch.f0, rtol=1e-15)  # F0 = k δ0^{3/2} (paper Eq. 1)
    # force equilibrium k δ0^{3/2} = F0 (paper below Eq. 9)
    assert np.ptp(med.f0) < 1e-12 * med.f0.max()
    # a law of another exponent than the static overlaps balance is refused
    with pytest.raises(ValueError, match="exponent"):
        ch.medium(theory.PowerLaw(2.0))


def test_gravity_and_free_ends():
    """Under gravity the static forces grow by m_i g per grain (F0_{j+1} - F0_j = m_j g,
    checked to 1e-12 relative); the free top contact (k = 0) is accepted."""
    sec = discrete.Section(40, D, theory.PAPER_MATERIAL)
    ch = discrete.Chain.from_sections([sec], gravity=9.81, left_wall=None)
    med = ch.medium()
    assert med.gravity == 9.81 and med.k[0] == 0 and med.precompressed
    f = med.f0
    np.testing.assert_allclose(np.diff(f), med.mass * 9.81, rtol=1e-12)
    # the same arrays without gravity violate the balance: refused, naming it
    with pytest.raises(ValueError, match="static balance"):
        Medium(med.mass, med.k, med.delta0, D)


def test_periodic_sections_are_handed_over():
    """A Periodic profile becomes a cell section (start, stop, cell length)."""
    cell = discrete.Periodic(((1.0, None), (0.5 ** (1 / 3), None)))
    ch = discrete.Chain.from_sections([discrete.Section(10, D, theory.PAPER_MATERIAL),
                                       discrete.Section(21, D, theory.PAPER_MATERIAL, cell)],
                                      delta0=1e-3 * D)
    assert ch.medium().cells == ((10, 31, 2),)


@pytest.mark.parametrize("n", [1, 3, 5, 9])
def test_discretisation_preserves_mass_and_compliance(n):
    med = two_section(6, 4, 1e-3 * D, 5.0, 0.2)
    disc = discretise(med, n)
    # a node on every grain centre, a face on every contact
    assert np.allclose(disc.x_nodes[disc.grain_nodes], np.arange(med.n_grains))
    assert np.allclose(disc.x_faces[disc.contact_faces], np.arange(med.n_grains + 1) - 0.5)
    # total mass and the compliance between the first and last grain centre are exact
    assert disc.h * disc.mass.sum() == pytest.approx(med.mass.sum(), rel=1e-14)
    inner = (disc.x_faces > 0) & (disc.x_faces < med.n_grains - 1)
    assert np.sum(disc.h / disc.stiffness[inner]) == pytest.approx(
        np.sum(1.0 / (1.5 * med.k[1:-1] * np.sqrt(med.delta0[1:-1]))), rel=1e-12)
    np.testing.assert_allclose(disc.f0, med.f0[0], rtol=1e-12)


def test_free_end_faces_take_the_next_contact():
    """A free end (k = 0): the faces of its half dual cell carry contact 1's constants."""
    ch = discrete.Chain.two_section(6, 0, 1.0, 1.0, 0.0, left_wall=None, right_wall=None)
    disc = discretise(ch.medium(), 3)
    assert np.all(disc.k > 0)
    np.testing.assert_array_equal(disc.k[:2], ch.k[1])
    np.testing.assert_array_equal(disc.k[-2:], ch.k[-2])


def test_bad_inputs_raise():
    med = Medium.uniform(5, 1e-6)
    with pytest.raises(ValueError, match="odd"):
        discretise(med, 4)
    with pytest.raises(ValueError, match=r"shape \(4,\)"):
        Medium(mass=np.ones(3), k=np.ones(3), delta0=np.zeros(3))
    with pytest.raises(ValueError, match="static balance"):
        Medium(mass=np.ones(2), k=np.array([1.0, 2.0, 1.0]), delta0=np.full(3, 1e-6))
    with pytest.raises(ValueError, match="drag"):
        Medium(med.mass, med.k, med.delta0, drag=-1.0)
    with pytest.raises(ValueError, match="k must be > 0"):
        Medium(np.ones(3), np.array([1.0, 0.0, 1.0, 1.0]), np.zeros(4))
    with pytest.raises(ValueError, match="cell section"):
        Medium(med.mass, med.k, med.delta0, cells=((3, 9, 2),))
    # the balance is checked to EQUILIBRIUM_RTOL: a relative error 10x beyond is refused
    d0 = med.delta0.copy()
    d0[2] *= 1 + 10 * EQUILIBRIUM_RTOL
    with pytest.raises(ValueError, match="static balance"):
        Medium(med.mass, med.k, d0)
