"""Phase-averaged kinetic/potential split of the Table 2 ratios (docs/physics.md §6).

A synthetic space-time grid of lattice waves with known phase-mean energies: a profile
g(z) sampled on the grains, Σ_i g(i - x) = ∫g + 2 Σ_k ĝ(2πk) cos(2πk x) (Poisson), so
the section sum of sech²(z/w) is 2w plus an oscillation of relative amplitude
2ĝ(2π)/ĝ(0) = 2π²w/sinh(π²w) with period one transit: 1.2e-2 at w = 0.8, 1.5e-3 at
w = 1.2.  The phase mean is exact up to exp(-2π²w) ~ 1e-7.
"""

import numpy as np
import pytest

from discrete import diagnostics as D

N_LEFT, N = 200, 400
WK, WP = 0.8, 1.2  # widths of the kinetic and potential profiles (grains)
EXACT = {"Ek_tr": 0.7, "Ep_tr": 0.4, "Ek_re": 0.1, "Ep_re": 0.2}


def sech2(z):
    q = np.exp(-2.0 * np.abs(z))
    return 4.0 * q / (1.0 + q) ** 2


def grid(row_dt: float, r_tr: float = 2.1, t_c: float = 150.0, t_end: float = 220.0):
    """Rows every ``row_dt`` transits: an incident wave at 1 grain per unit time that
    reaches the interface (grain 200) at t_c, then a transmitted wave at r_tr and a
    reflected one at -0.6 grains per unit time leaving it, with the split of EXACT
    (phase means)."""
    t = np.arange(0.0, t_end, row_dt)
    i = np.arange(N)
    ek, ep = np.zeros((t.size, N)), np.zeros((t.size, N))
    for j, tj in enumerate(t):
        if tj < t_c:
            x = 50.0 + tj
            ek[j] = sech2((i - x) / WK)
            ep[j] = 0.5 * sech2((i - x) / WP)
        else:
            xr, xl = 200.0 + r_tr * (tj - t_c), 200.0 - 0.6 * (tj - t_c)
            right, left = i >= N_LEFT, i < N_LEFT
            ek[j] = right * EXACT["Ek_tr"] * sech2((i - xr) / WK) \
                + left * EXACT["Ek_re"] * sech2((i - xl) / WK)
            ep[j] = right * EXACT["Ep_tr"] * 0.5 * sech2((i - xr) / WP) \
                + left * EXACT["Ep_re"] * 0.5 * sech2((i - xl) / WP)
    return t, ek, ep, (i >= N_LEFT).astype(int)


def test_phase_window_is_blackman_harris_and_refuses_an_empty_window():
    t = np.linspace(0.0, 1.0, 101)
    rows, w = D.phase_window(t, 0.0, 1.0)
    assert rows.size == 101
    # Harris (1978) 4-term: w(0) = a0 - a1 + a2 - a3 = 6e-5, w(1/2) = Σa = 1
    assert w[0] == pytest.approx(6e-5, abs=1e-12) and w[50] == pytest.approx(1.0, abs=1e-12)
    # a sinusoid 5 bins out is removed to the side-lobe level (-92 dB)
    y = 1.0 + 0.3 * np.cos(2 * np.pi * 5.3 * t + 0.4)
    t2 = np.linspace(0.0, 1.0, 2001)
    r2, w2 = D.phase_window(t2, 0.0, 1.0)
    y2 = 1.0 + 0.3 * np.cos(2 * np.pi * 5.3 * t2 + 0.4)
    assert abs((w2 @ y2[r2]) / w2.sum() - 1.0) < 0.3 * 3e-5
    assert abs((w @ y[rows]) / w.sum() - 1.0) < 0.3 * 3e-5
    with pytest.raises(ValueError, match="stop must be > start"):
        D.phase_window(t, 1.0, 1.0)


def test_single_rows_oscillate_with_the_phase_the_window_does_not():
    t, ek, ep, sec = grid(0.3)
    e = ek + ep
    i_in = D.incident_time_index(e, N_LEFT)
    i_out = D.separated_time_index(e, N_LEFT, fraction=1e-6)
    assert i_out is not None
    # the old rule: one row each; moving the rows by a fraction of a transit moves it
    single = [D.energy_ratios_from_grid(ek, ep, sec, i_in - k, i_out + k).Ek_tr
              for k in range(4)]
    assert np.ptp(single) > 5e-3, single  # the 1.2e-2 oscillation of both sums
    r, est = D.phase_averaged_ratios(t, ek, ep, sec, i_in, i_out)
    for key, val in EXACT.items():
        # exact up to the window's side lobes on the 1.2e-2 oscillation (~3e-7)
        assert getattr(r, key) == pytest.approx(val, abs=1e-6), key
    assert est < 1e-6
    # the same with the rows shifted by a third of a row: the phase changes, not the mean
    t2, ek2, ep2, _ = grid(0.3, t_c=150.1, t_end=220.1)
    e2 = ek2 + ep2
    r2, _ = D.phase_averaged_ratios(t2, ek2, ep2, sec, D.incident_time_index(e2, N_LEFT),
                                    D.separated_time_index(e2, N_LEFT, fraction=1e-6))
    assert r2.Ek_tr == pytest.approx(r.Ek_tr, abs=2e-6)


def test_aliased_rows_are_flagged_by_the_estimate():
    # rows half a transit apart alias the transmitted wave (2.1 grains per unit time)
    # to 0.1 per unit time, inside the window's main lobe: the mean is off, and the
    # estimate (3/4 window about the same centre) must say so
    t, ek, ep, sec = grid(0.5)
    e = ek + ep
    i_in = D.incident_time_index(e, N_LEFT)
    i_out = D.separated_time_index(e, N_LEFT, fraction=1e-6)
    r, est = D.phase_averaged_ratios(t, ek, ep, sec, i_in, i_out, transit=1.0)
    err = max(abs(getattr(r, k) - v) for k, v in EXACT.items())
    assert err > 1e-4  # aliased: not averaged
    assert est >= 0.3 * err, (est, err)


def test_phase_averaged_ratios_refuses_bad_input():
    t, ek, ep, sec = grid(0.3, t_end=170.0)
    with pytest.raises(ValueError, match="window"):
        D.phase_averaged_ratios(t, ek, ep, sec, 10, 20, window=0.0)
    with pytest.raises(ValueError, match="weights"):
        D.energy_ratios_from_grid(ek, ep, sec, [1, 2], [3, 4], w_incident=[1.0, -1.0])
