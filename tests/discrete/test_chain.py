"""Chain construction and validation."""

import numpy as np
import pytest

import theory
from discrete import Chain, Section


def test_two_section_paper_setup():
    ch = Chain.two_section(400, 400, alpha_rho=5.0, alpha_kn=0.2, delta0_over_d=1e-3)
    mat = theory.PAPER_MATERIAL
    kl = theory.hertz_constant(5e-3, mat)
    kr = theory.hertz_constant(5e-3, mat.scaled(5.0, 0.2))
    assert ch.n == 800 and ch.k.shape == (801,) and ch.delta0.shape == (801,)
    assert ch.k[1] == pytest.approx(kl, rel=1e-14) and ch.k[-2] == pytest.approx(kr, rel=1e-14)
    # interface contact 400 (grains 399|400): harmonic mean for equal diameters
    assert ch.k[400] == pytest.approx(2 * kl * kr / (kl + kr), rel=1e-12)
    assert ch.k[0] == ch.k[1] and ch.k[-1] == ch.k[-2]  # "paper" walls
    # force equilibrium: every static force equal, δ0^L = 1e-3 d, δ0^R = α_kn^{-2/3} δ0^L
    np.testing.assert_allclose(ch.f0, ch.f0[1], rtol=1e-13)
    assert ch.delta0[1] == 5e-6
    assert ch.delta0[-2] == pytest.approx(5e-6 * 0.2 ** (-2 / 3), rel=1e-13)
    assert ch.mass[-1] == pytest.approx(5 * ch.mass[0], rel=1e-14)
    assert [s.start for s in ch.section_slices()] == [0, 400]
    assert ch.params["alpha_rho"] == 5.0 and ch.params["kind"] == "two_section"


def test_walls_and_free_ends():
    mat = theory.PAPER_MATERIAL
    sec = [Section(10, 5e-3, mat)]
    hz = Chain.from_sections(sec, left_wall="hertz", right_wall=None)
    assert hz.k[0] == pytest.approx(theory.hertz_constant_wall(5e-3, mat))
    assert hz.k[-1] == 0 and hz.delta0[-1] == 0
    with pytest.raises(ValueError, match="both walls"):
        Chain.from_sections(sec, delta0=1e-6, right_wall=None)
    with pytest.raises(ValueError, match="left_wall"):
        Chain.from_sections(sec, left_wall="glue")
    byforce = Chain.from_sections(sec, wall_force=10.0)
    np.testing.assert_allclose(byforce.f0, 10.0, rtol=1e-13)


def test_from_arrays_dimer_and_tapered():
    n = 40
    mass = np.where(np.arange(n) % 2, 1e-4, 5e-4)
    ch = Chain.from_arrays(mass, np.full(n + 1, 3e9), 1e-6)
    assert ch.delta0[1] == 1e-6 and ch.n == n
    taper = Chain.from_arrays(np.geomspace(1e-3, 1e-4, n), np.geomspace(5e9, 2e9, n + 1), 1e-6)
    np.testing.assert_allclose(taper.f0, taper.f0[1], rtol=1e-13)


@pytest.mark.parametrize("kwargs, match", [
    ({"mass": [1.0]}, "N >= 2"),
    ({"mass": [1.0, -1.0]}, "mass must be > 0"),
    ({"mass": [1.0, np.nan]}, "finite"),
    ({"k": [1.0, 0.0, 1.0]}, "grain-grain contacts"),
    ({"k": [1.0, 1.0]}, "shape"),
    ({"delta0": [0.0, -1e-6, 0.0]}, ">= 0"),
    ({"delta0": np.nan}, "delta0"),
    ({"diameter": [5e-3, 0.0]}, "diameter must be > 0"),
])
def test_bad_chain_input(kwargs, match):
    args = {"mass": [1e-3, 1e-3], "k": [1e9, 1e9, 1e9], "delta0": 0.0, **kwargs}
    with pytest.raises(ValueError, match=match):
        Chain.from_arrays(args.pop("mass"), args.pop("k"), args.pop("delta0"), **args)


def test_bad_sections():
    with pytest.raises(ValueError, match="Section.n"):
        Section(0, 5e-3, theory.PAPER_MATERIAL)
    with pytest.raises(ValueError, match="diameter"):
        Section(3, -1.0, theory.PAPER_MATERIAL)
    with pytest.raises(ValueError, match="N >= 2"):
        Chain.two_section(1, 0)
    with pytest.raises(ValueError, match="n_left"):
        Chain.two_section(0, 5)
    with pytest.raises(ValueError, match="delta0_over_d"):
        Chain.two_section(5, 5, delta0_over_d=-1e-3)
    with pytest.raises(ValueError, match="alpha_rho"):
        Chain.two_section(5, 5, alpha_rho=0.0)


def test_different_diameters_use_two_sphere_hertz_rule():
    steel, soft = theory.PAPER_MATERIAL, theory.PAPER_MATERIAL.scaled(0.3, 0.1)
    ch = Chain.from_sections([Section(5, 5e-3, steel), Section(5, 3e-3, soft)], delta0=1e-6)
    assert ch.k[5] == pytest.approx(theory.hertz_constant(5e-3, steel, 3e-3, soft), rel=1e-14)
    np.testing.assert_allclose(ch.f0, ch.f0[1], rtol=1e-13)
    assert ch.mass[5] == pytest.approx(theory.grain_mass(3e-3, steel.density * 0.3))
    np.testing.assert_allclose(ch.positions[4:6], [22.5e-3, 26.5e-3])
