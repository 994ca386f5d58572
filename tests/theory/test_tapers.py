"""Tapered chains (theory.tapers): binary collisions and the adiabatic wave against the
two-body problem and the discrete chain of the shipped tapered scenarios."""

import tomllib

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import theory
from discrete import Recording, WaveAt
from discrete.initial import impact
from hertzchain.runner import build_chain
from hertzchain.scenario import parse_scenario, shipped_scenarios
from theory import tapers as T

EXAMPLES = shipped_scenarios()


@pytest.mark.parametrize("m1, m2, n", [(1e-3, 1e-3, 1.5), (2e-3, 0.5e-3, 1.5),
                                       (0.5e-3, 2e-3, 2.0), (1e-3, np.inf, 1.5)])
def test_binary_collision_is_the_two_body_problem(m1, m2, n):
    # The closed forms (time to the largest overlap, largest overlap and force, final
    # velocities) against the two-body equations integrated to 1e-12 (measured ≤ 1e-9;
    # tolerance 1e-7).  m2 = inf: a rigid wall.
    k, v = 1e10, 0.7
    inv2 = 0.0 if np.isinf(m2) else 1 / m2

    def rhs(_t, y):
        f = k * max(y[0], 0.0) ** n  # y = (overlap, v1, v2)
        return [y[1] - y[2], -f / m1, f * inv2]

    peak = lambda _t, y: y[1] - y[2]  # noqa: E731 (the overlap rate vanishes)
    peak.terminal = False
    sep = lambda _t, y: y[0] + 1e-30 if _t > 0 else 1.0  # noqa: E731
    sep.terminal, sep.direction = True, -1
    c = T.binary_collision(m1, m2, k, v, exponent=n)
    sol = solve_ivp(rhs, (0, 20 * c.time_to_max), [0.0, v, 0.0], events=(peak, sep),
                    rtol=1e-12, atol=1e-20, method="DOP853")
    t_peak = sol.t_events[0][0]
    assert c.time_to_max == pytest.approx(t_peak, rel=1e-7)
    assert c.max_overlap == pytest.approx(sol.y_events[0][0][0], rel=1e-7)
    assert c.max_force == pytest.approx(k * sol.y_events[0][0][0] ** n, rel=1e-7)
    assert c.velocity_striker == pytest.approx(sol.y_events[1][0][1], rel=1e-7, abs=1e-9)
    assert c.velocity_struck == pytest.approx(sol.y_events[1][0][2], rel=1e-7, abs=1e-9)
    assert sol.t_events[1][0] == pytest.approx(2 * t_peak, rel=1e-7)  # time-symmetric


def test_sonic_vacuum_constants_scale_and_obey_the_virial_theorem():
    # The constants of the exact wave (k = m = d = v = 1; theory.profiles, which the
    # adiabatic taper wave scales) rescale to any grains and amplitude (self-similarity
    # of the δ0 = 0 wave): against a wave computed directly for steel grains at 0.3 m/s,
    # energy, momentum, amplitude and speed to 1e-9.  The phase-averaged kinetic energy is
    # (n+1)/(n+3) of the total (virial theorem, 2⟨K⟩ = (n+1)⟨U⟩): measured to 1e-14,
    # tolerance 1e-10.  rate/amplitude^{(n-1)/2} is the speed constant V/(c ξ^{(n-1)/2})
    # of theory.discrete_speed_constant (measured 1e-15; tolerance 1e-12).
    mat, d = theory.PAPER_MATERIAL, 3e-3
    m, k = theory.grain_mass(d, mat.density), theory.hertz_constant(d, mat)
    for n in (1.5, 2.0, 3.0):
        c = theory.sonic_vacuum_wave_constants(n)
        w = theory.discrete_solitary_wave(k, m, d, velocity_max=0.3, exponent=n)
        u = 0.3 * np.sqrt(m / k)
        assert w.energy() == pytest.approx(c.energy * m * 0.09, rel=1e-9)
        assert w.momentum() == pytest.approx(c.momentum * m * 0.3, rel=1e-9)
        assert w.amplitude == pytest.approx(c.amplitude * u ** (2 / (n + 1)), rel=1e-9)
        assert w.speed == pytest.approx(
            c.rate * d * np.sqrt(k / m) * u ** ((n - 1) / (n + 1)), rel=1e-9)
        assert c.kinetic_fraction == pytest.approx((n + 1) / (n + 3), rel=1e-10)
        assert c.rate / c.amplitude ** ((n - 1) / 2) == pytest.approx(
            theory.discrete_speed_constant(exponent=n), rel=1e-12)


def _tapered(stem, q=None):
    """A shipped tapered scenario's chain (the last section's mass_ratio set to q)."""
    with open(EXAMPLES[stem], "rb") as f:
        data = tomllib.load(f)
    if q is not None:
        sec = data["chain"]["sections"][-1]
        if q == 1:
            del sec["profile"], sec["mass_ratio"]
        else:
            sec["mass_ratio"] = q
    return build_chain(parse_scenario(data).chain)


def test_taper_ratios_are_those_of_the_grain_by_grain_estimates():
    # geometric_taper_ratios against bca_velocities / adiabatic_taper_wave on the shipped
    # chain_tapered_bca chain (q = 0.98, spheres of one material: d ∝ m^{1/3}, k ∝ √d),
    # to rounding; both velocity factors agree to first order in 1 - q.
    ch = _tapered("chain_tapered_bca")
    q = ch.mass[-1] / ch.mass[-2]
    r = T.geometric_taper_ratios(q)
    v = T.bca_velocities(ch.mass, 1.0)
    np.testing.assert_allclose(v[31:] / v[30:-1], r.bca_velocity, rtol=1e-13)
    w = T.adiabatic_taper_wave(ch.mass, ch.k[1:-1], ch.diameter, 1e-4)
    sl = slice(32, None)
    np.testing.assert_allclose(w.velocity_max[sl] / w.velocity_max[31:-1], r.adiabatic_velocity,
                               rtol=1e-12)
    np.testing.assert_allclose(w.force_max[sl] / w.force_max[31:-1], r.adiabatic_force,
                               rtol=1e-12)
    np.testing.assert_allclose(w.speed[sl] / w.speed[31:-1], r.adiabatic_speed, rtol=1e-12)
    assert r.adiabatic_force == pytest.approx(q ** (1 / 15)) and r.bca_energy < 1
    for qq in (0.999, 0.99):
        rr = T.geometric_taper_ratios(qq)
        assert abs(rr.bca_velocity / rr.adiabatic_velocity - 1) < (1 - qq) ** 2


def test_bca_speed_on_a_uniform_chain():
    # d/t_max = 0.8201 c^{4/5} v0^{1/5} (Hertz, c² = k d^{5/2}/m), against 0.8405 for the
    # solitary wave of an impact at v0 (v_max = 0.6816 v0, exact wave: 0.9075 c^{4/5}
    # v_max^{1/5}): 2.4 % slower.
    mat, d = theory.PAPER_MATERIAL, 5e-3
    m, k = theory.grain_mass(d, mat.density), theory.hertz_constant(d, mat)
    c = np.sqrt(k * d**2.5 / m)
    t = T.bca_arrival_times(np.full(11, m), np.full(10, k), 0.5)
    speed = 10 * d / t[-1]
    assert speed / (c**0.8 * 0.5**0.2) == pytest.approx(0.8201, abs=1e-4)
    cw = theory.sonic_vacuum_wave_constants()
    assert cw.rate * 0.6816**0.2 == pytest.approx(0.8405, abs=1e-4)


def _run(ch):
    sim = impact(ch, 1.0).simulation(record=Recording(refined_maxima=True,
                                                      monitor_every=10**6))
    sim.run(until=WaveAt(ch.n - 2), progress=False)
    return sim.record.vmax_time, sim.record.vmax_refined


@pytest.mark.parametrize("stem, q, growth_tol, adiabatic_tol, bca_tol", [
    ("chain_tapered_bca", None, 1e-4, 0.005, 0.035),
    ("chain_tapered_bca", 0.95, 5e-4, 0.01, 0.04),
    ("chain_tapered_bca", 0.9, 2e-3, 0.015, 0.05),
    ("chain_tapered_bca", 1.05, 2e-4, 0.012, 0.03),
    ("chain_tapered_backward", None, 2e-4, 0.02, 0.03),
])
def test_tapered_chain_against_bca_and_adiabatic_wave(stem, q, growth_tol, adiabatic_tol,
                                                      bca_tol):
    # The shipped tapered scenarios (chain_tapered_bca: 30 uniform + 40 tapered steel
    # grains, d = 15 mm, q = 0.98 as shipped, 0.95, 0.9 and backward 1.05;
    # chain_tapered_backward: 30 grains, q = 1.05), grain 0 struck at 1 m/s, run until
    # the pulse reaches the last grains.  Measured:
    # * growth of the peak grain velocity per grain along the taper (least squares on
    #   ln v_max) against the BCA's 2/(1+q): 2.6e-5, 2.2e-4, 1.3e-3, 7.7e-5, 8.3e-5
    #   (the adiabatic q^{-1/2}: 7.7e-5, 5.5e-4, 2.7e-3, 3.7e-4, 3.8e-4);
    # * arrival times of the peak from grain 25 (5 in the backward chain), largest
    #   relative error along the taper: adiabatic wave 0.29 %, 0.67 %, 1.19 %, 0.90 %,
    #   1.42 %; BCA 2.95 %, 3.61 %, 4.58 %, 2.10 %, 2.20 % (2.49 % on the uniform
    #   chain: the BCA pulse is 2.4 % slow);
    # * the adiabatic peak velocity is 1.2 %, 4.4 %, 15 % high at the small end of the
    #   forward tapers (the wave sheds a tail, a loss first order in 1 - q).
    ch = _tapered(stem, q)
    t, vmax = _run(ch)
    n_taper = 40 if stem == "chain_tapered_bca" else 30
    first = ch.n - n_taper
    ref = max(first - 5, 5)
    qq = ch.mass[-1] / ch.mass[-2]
    k = np.arange(first + 10, ch.n - 5)
    growth = np.exp(np.polyfit(k, np.log(vmax[k]), 1)[0])
    r = T.geometric_taper_ratios(qq)
    assert growth == pytest.approx(r.bca_velocity, rel=growth_tol)
    e = theory.sonic_vacuum_wave_constants().energy * ch.mass[ref] * vmax[ref] ** 2
    wave = T.adiabatic_taper_wave(ch.mass, ch.k[1:-1], ch.diameter, e, start=ref)
    tb = T.bca_arrival_times(ch.mass, ch.k[1:-1], 1.0)
    i = np.arange(max(first + 3, ref + 1), ch.n - 4)
    measured = t[i] - t[ref]
    assert np.max(np.abs(wave.arrival_time[i] / measured - 1)) < adiabatic_tol
    assert np.max(np.abs((tb[i] - tb[ref]) / measured - 1)) < bca_tol
    assert np.all((tb[i] - tb[ref]) > measured)  # the BCA pulse is always late


def test_bad_input_names_the_parameter():
    with pytest.raises(ValueError, match="masses"):
        T.bca_velocities([1.0, -1.0], 1.0)
    with pytest.raises(ValueError, match="m2"):
        T.binary_collision(1.0, 0.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="k_contacts"):
        T.bca_arrival_times([1.0, 1.0, 1.0], [1.0], 1.0)
    with pytest.raises(ValueError, match="q"):
        T.geometric_taper_ratios(0.0)
    with pytest.raises(ValueError, match="start"):
        T.adiabatic_taper_wave([1.0, 1.0], [1.0], [1.0, 1.0], 1.0, start=2)
