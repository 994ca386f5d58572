"""Wave speeds: paper Eqs. 4, 5, 7, 8 and Nesterenko's general relation."""

import warnings

import numpy as np
import pytest

import theory

D = 5e-3
MAT = theory.PAPER_MATERIAL
M = theory.grain_mass(D, MAT.density)
K = theory.hertz_constant(D, MAT)


def test_c0_is_lattice_sound_speed():
    # c0 = d sqrt(K_lin/m) with K_lin = dF/d delta = 3/2 k delta0^{1/2}  (Eq. 4)
    delta0 = 1e-3 * D
    k_lin = 1.5 * K * np.sqrt(delta0)
    assert theory.c0(K, M, D, delta0) == pytest.approx(D * np.sqrt(k_lin / M), rel=1e-14)
    # derivative of the force numerically (independent of the closed form)
    h = delta0 * 1e-6
    k_num = (K * (delta0 + h) ** 1.5 - K * (delta0 - h) ** 1.5) / (2 * h)
    assert theory.linear_stiffness(K, delta0) == pytest.approx(k_num, rel=1e-9)
    # long-wave limit of the lattice dispersion omega = 2 c0/d sin(kd/2)
    c = theory.c0(K, M, D, delta0)
    kk = 1e-3 / D
    assert theory.lattice_dispersion(kk, c, D) / kk == pytest.approx(c, rel=1e-6)


def test_c0_cmat_relation():
    # c0^2 = 3/2 c_mat^2 xi0^{1/2}
    xi0 = 1e-3
    lhs = theory.c0(K, M, D, xi0 * D) ** 2
    rhs = 1.5 * theory.c_mat(K, M, D) ** 2 * np.sqrt(xi0)
    assert lhs == pytest.approx(rhs, rel=1e-13)


def test_nesterenko_tends_to_eq5_small_amplitude():
    cm = theory.c_mat(K, M, D)
    xi0 = 1e-3
    c = theory.c0(K, M, D, xi0 * D)
    for eps in (1e-2, 1e-3, 1e-4):
        xi = eps * xi0
        v_gen = theory.nesterenko_speed(cm, xi0, xi)
        v5 = theory.kdv_speed(c, D, xi0 * D, xi)
        # Series: V/c0 = sqrt(1 + eps/6 - eps^2/48 + ...) = 1 + eps/12 - eps^2/72 + O(eps^3),
        # so Eq. 5 is the first-order term and the remainder / eps^2 -> -1/72.
        assert (v_gen / v5 - 1) / eps**2 == pytest.approx(-1 / 72, rel=0.05)
    # and the series branch joins the closed form continuously at eps = 1e-3
    lo = theory.nesterenko_speed(cm, xi0, xi0 * (1e-3 - 1e-12))
    hi = theory.nesterenko_speed(cm, xi0, xi0 * (1e-3 + 1e-12))
    assert lo == pytest.approx(hi, rel=1e-9)


def test_nesterenko_tends_to_eq8_large_amplitude():
    cm = theory.c_mat(K, M, D)
    xi = 1e-3
    v8 = theory.sonic_vacuum_speed(cm, xi)
    assert theory.nesterenko_speed(cm, 0.0, xi) == pytest.approx(v8, rel=1e-14)
    rels = [abs(theory.nesterenko_speed(cm, xi / f, xi) / v8 - 1) for f in (1e2, 1e4, 1e6)]
    # relative difference falls monotonically towards 0 as the precompression vanishes
    assert rels[0] > rels[1] > rels[2]
    assert rels[2] < 1e-2


@pytest.mark.parametrize("n", [1.5, 2.0, 4.0, 10.0])
def test_nesterenko_speed_as_the_precompression_vanishes(n):
    # δ0 → 0 down to the smallest subnormal ξ0: finite, no floating-point warning (the
    # suite raises on them), and the compacton's speed.  With ε = ξ_max/ξ0,
    # (V/V_vac)² = R(ε)/ε^{n+1} = (1 + 1/ε)^{n+1} - (n+1) ε^{-n} - ε^{-n-1}
    # (R(ε) = (1+ε)^{n+1} - 1 - (n+1)ε), evaluated here in that form, cancellation-free:
    # at ε = 1e4 … 1e8 to 1e-4 of V/V_vac - 1 (the rounding of V/V_vac, ~1e-14, is ≤ 1e-6
    # of it).  Beyond ε = 1e18 (where V/V_vac - 1 ≈ (n+1)/(2ε) < 1e-17) the function
    # returns V_vac itself, continuous at the switch to the formula's rounding (measured
    # ≤ 2.2e-14; tolerance 1e-13).
    c, xm = 300.0, 1e-4
    v_vac = theory.sonic_vacuum_speed(c, xm, exponent=n)
    xi0 = np.r_[10.0 ** -np.arange(6.0, 309.0, 3.0), 1e-310, 5e-324]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        v = theory.nesterenko_speed(c, xi0, xm, exponent=n)
        v_far = theory.nesterenko_speed(c, xi0 * 1e-5, 1.0, exponent=n)
    assert np.all(np.isfinite(v)) and np.all(np.isfinite(v_far))
    assert np.all(v[xi0 * 1e18 < xm] == v_vac)
    # falls onto V_vac (monotonic up to the formula's rounding, 1e-15 relative)
    assert np.all(np.diff(v) <= 1e-14 * v_vac) and np.all(v >= v_vac * (1 - 1e-14))
    for eps in (1e4, 1e6, 1e8):
        x = np.expm1((n + 1) * np.log1p(1 / eps)) - (n + 1) * eps**-n - eps ** -(n + 1)
        rel = theory.nesterenko_speed(c, xm / eps, xm, exponent=n) / v_vac - 1
        assert rel == pytest.approx(x / (1 + np.sqrt(1 + x)), rel=1e-4)
    lo, hi = (theory.nesterenko_speed(c, xm / e, xm, exponent=n) for e in
              (1e18 * (1 - 1e-12), 1e18 * (1 + 1e-12)))
    assert abs(hi / lo - 1) < 1e-13


def test_kdv_exact_vs_eq5():
    c = 900.0
    # V = c0 sqrt(1 + d xi/(6 delta0)) agrees with Eq. 5 to first order
    v = theory.kdv_speed_exact(c, D, 5e-6, 1e-7)
    assert v == pytest.approx(theory.kdv_speed(c, D, 5e-6, 1e-7), rel=1e-8)


def test_speed_validation():
    with pytest.raises(ValueError, match="delta0"):
        theory.c0(K, M, D, 0.0)
    with pytest.raises(ValueError, match="xi_max"):
        theory.sonic_vacuum_speed(1.0, -1e-3)
    with pytest.raises(ValueError, match="mass"):
        theory.c_mat(K, -M, D)
