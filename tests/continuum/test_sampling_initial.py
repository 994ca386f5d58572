"""Initial conditions and grain sampling: round trips, closed forms, energy definitions."""

import numpy as np
import pytest

import theory
from continuum import (
    BoussinesqPDE,
    Medium,
    NesterenkoPDE,
    compacton,
    compacton_parameters,
    from_grains,
    sample_grains,
    section_energies,
    solitary_wave,
    solitary_wave_parameters,
)

from ._helpers import two_section

D = theory.PAPER_DIAMETER


def test_from_grains_round_trip(rng):
    """Splines through the grain centres: sampling returns the grain values exactly."""
    med = two_section(20, 15, 1e-3 * D, 2.0, 0.5)
    pde = BoussinesqPDE(med, 5)
    u = 1e-7 * np.cumsum(rng.random(35))
    v = rng.standard_normal(35)
    smp = sample_grains(pde, from_grains(pde, u, v))
    np.testing.assert_allclose(smp.u, u, rtol=1e-13)
    np.testing.assert_allclose(smp.v, v, rtol=1e-13)
    # discrete definitions (paper Eq. 1, Table 2)
    overlap = med.delta0 + np.r_[0.0, u[:-1] - u[1:], 0.0]  # free ends keep δ0
    np.testing.assert_allclose(smp.overlap, overlap, rtol=1e-13)
    np.testing.assert_allclose(smp.kinetic, 0.5 * med.mass * v**2)
    np.testing.assert_allclose(smp.potential,
                               0.4 * med.k * (overlap**2.5 - med.delta0**2.5))
    sec = section_energies(smp, 20)
    total = smp.kinetic.sum() + smp.potential.sum()
    assert sec["left"]["total"] + sec["right"]["total"] == pytest.approx(total)
    assert sec["left"]["potential_linear"] == pytest.approx(
        (med.f0[:20] * smp.strain[:20]).sum() + 0.5 * med.f0[20] * smp.strain[20])


def test_solitary_wave_matches_closed_form():
    """sech² strain, v = V s, amplitude from v_max, speed √(1 + A/(6δ0)) c0 (Eq. 5 to
    first order; theory.kdv_speed_exact)."""
    med = Medium.uniform(100, 1e-3 * D)
    pde = BoussinesqPDE(med, 3)
    par = solitary_wave_parameters(pde, 50.0, velocity_max=0.0822)
    assert par["velocity_max"] == pytest.approx(0.0822, rel=1e-10)
    c0 = theory.c0(med.k[1], med.mass[0], D, med.delta0[1])
    assert par["speed_m_s"] == pytest.approx(
        theory.kdv_speed_exact(c0, D, par["delta0"], par["amplitude"] / D), rel=1e-12)
    state = solitary_wave(pde, 50.0, velocity_max=0.0822)
    s = pde.strain(state[0].data)
    xf = pde.disc.x_faces
    exact = par["amplitude"] / np.cosh((xf - 50.0) / par["width"]) ** 2
    exact[[0, -1]] = 0.0  # free ends
    assert np.max(np.abs(s - exact)) < 5e-3 * par["amplitude"]  # O(h²/Λ²) differences
    assert state[1].data.max() == pytest.approx(0.0822, rel=1e-3)


def test_compacton_closed_form():
    """ξ = ξm cos⁴(√10 X/5) and V = (2/√5) c_mat ξm^{1/4} (Eq. 8); v = V ξ."""
    med = Medium.uniform(30, 0.0)
    pde = NesterenkoPDE(med, 5, delta_floor=0.0)
    par = compacton_parameters(pde, velocity_max=0.68)
    assert par["velocity_max"] == pytest.approx(0.68)
    assert par["speed_m_s"] == pytest.approx(
        theory.sonic_vacuum_speed(theory.c_mat(med.k[1], med.mass[0], D), par["strain_max"]))
    state = compacton(pde, 12.0, velocity_max=0.68)
    xf = pde.disc.x_faces
    th = np.clip((xf - 12.0) * np.sqrt(10) / 5, -np.pi / 2, np.pi / 2)
    s = pde.strain(state[0].data)
    assert np.max(np.abs(s - par["amplitude"] * np.cos(th) ** 4)) < 0.01 * par["amplitude"]
    assert np.all(state[0].data >= 0)
    assert state[0].data[-1] == 0.0  # nothing displaced ahead of the wave
