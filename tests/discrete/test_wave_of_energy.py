"""The exact lattice wave of a given energy (``discrete.waves._wave_of_energy``).

At δ0 = 0 it is the closed form of the self-similar family (Nesterenko 2001 §1.1;
English & Pego 2005): E = ê m v_max².  Checked against an independent root finding of
E(v_max) = E on :func:`theory.discrete_solitary_wave` (Brent's method to 1e-14 in ln v);
the two agree to 1e-12 (the energy of the exact wave is phase independent to 7e-15,
its rescaling exact up to round-off).  The scaling itself is checked on the solver's
output, and the precompressed path (root finding) on the energy it must reproduce.
"""

import math

import pytest
from scipy.optimize import brentq

from discrete.waves import _wave_of_energy
from theory import discrete_solitary_wave

CASES = [  # k (N/m^n), m (kg), d (m), E (J), sampled-peak guess (m/s)
    (1.2e10, 1.0e-3, 1.0e-2, 1.0e-4, 0.3),
    (3.3e9, 2.2e-4, 8.0e-3, 3.0e-7, 0.05),
    (1.0, 1.0, 1.0, 2.0, 1.0),
]


def _rooted(k, m, d, delta0, n, energy):
    """The wave of ``energy`` by Brent's method on ln E(v_max) − ln E (independent path)."""
    def f(lv):
        w = discrete_solitary_wave(k, m, d, delta0, velocity_max=math.exp(lv), exponent=n)
        return math.log(w.energy() / energy)

    lv = brentq(f, -30.0, 30.0, xtol=1e-14, rtol=1e-15)
    return discrete_solitary_wave(k, m, d, delta0, velocity_max=math.exp(lv), exponent=n)


@pytest.mark.parametrize("n", [1.5, 2.0, 2.5, 1.2])
@pytest.mark.parametrize("case", CASES)
def test_sonic_vacuum_closed_form_matches_root_finding(n, case):
    k, m, d, energy, guess = case
    w = _wave_of_energy(k, m, d, 0.0, n, energy, guess)
    ref = _rooted(k, m, d, 0.0, n, energy)
    for name in ("velocity_max", "amplitude", "speed"):
        assert getattr(w, name) == pytest.approx(getattr(ref, name), rel=1e-12), name
    assert w.energy() == pytest.approx(energy, rel=1e-12)


@pytest.mark.parametrize("n", [1.5, 2.5])
def test_self_similar_scaling(n):
    # v_max -> mu v_max: overlaps x mu^(2/(n+1)), speed x mu^((n-1)/(n+1)), energy x mu^2
    k, m, d = 5e9, 3e-4, 6e-3
    mu = 7.3
    a = discrete_solitary_wave(k, m, d, velocity_max=0.2, exponent=n)
    b = discrete_solitary_wave(k, m, d, velocity_max=0.2 * mu, exponent=n)
    assert b.amplitude / a.amplitude == pytest.approx(mu ** (2 / (n + 1)), rel=1e-13)
    assert b.speed / a.speed == pytest.approx(mu ** ((n - 1) / (n + 1)), rel=1e-13)
    assert b.energy() / a.energy() == pytest.approx(mu**2, rel=1e-13)


def test_precompressed_wave_carries_the_energy():
    # δ0 > 0: no single scaling (ε = A/δ0 is a second parameter): root finding, to 1e-10
    # in ln v, i.e. the energy to ~1e-10 (2e-10 allowed)
    k, m, d, delta0 = 1.2e10, 1.0e-3, 1.0e-2, 1e-5
    guess = 0.05
    ref = discrete_solitary_wave(k, m, d, delta0, velocity_max=0.06)
    w = _wave_of_energy(k, m, d, delta0, 1.5, ref.energy(), guess)
    assert w.energy() == pytest.approx(ref.energy(), rel=2e-10)
    assert w.velocity_max == pytest.approx(0.06, rel=1e-9)


@pytest.mark.parametrize("energy, guess", [(0.0, 1.0), (1.0, 0.0), (-1.0, 1.0)])
def test_no_wave_without_energy_or_velocity(energy, guess):
    with pytest.raises(ValueError, match="no wave"):
        _wave_of_energy(1.0, 1.0, 1.0, 0.0, 1.5, energy, guess)
