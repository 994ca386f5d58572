"""Interface predictions: paper Eqs. 9-13 and the regions of Fig. 7."""

import json

import numpy as np
import pytest

import theory
from hertzchain.cli import main

D = 5e-3
MAT = theory.PAPER_MATERIAL


def _section_c0_and_impedance(alpha_rho, alpha_kn, delta0_left=5e-6):
    """c0 and R_G = rho c0 computed from material parameters (no Eq. 9/13)."""
    right = MAT.scaled(alpha_rho, alpha_kn)
    out = []
    k_l, k_r = theory.hertz_constant(D, MAT), theory.hertz_constant(D, right)
    d_l, d_r = theory.static_overlaps([k_l, k_r], delta0=delta0_left)
    for mat, k, dl in ((MAT, k_l, d_l), (right, k_r, d_r)):
        m = theory.grain_mass(D, mat.density)
        c = theory.c0(k, m, D, dl)
        out.append((c, mat.density * c))
    return out


@pytest.mark.parametrize("alpha_rho", [0.2, 0.7, 1.0, 3.0, 5.0])
@pytest.mark.parametrize("alpha_kn", [0.2, 1.0, 2.8, 5.0])
def test_eq9_eq13_from_parameters(alpha_rho, alpha_kn):
    (c_l, z_l), (c_r, z_r) = _section_c0_and_impedance(alpha_rho, alpha_kn)
    assert theory.gamma_c0(alpha_rho, alpha_kn) == pytest.approx(c_r / c_l, rel=1e-12)
    assert theory.gamma_rg(alpha_rho, alpha_kn) == pytest.approx(z_r / z_l, rel=1e-12)


@pytest.mark.parametrize("g", [0.2, 0.5, 1.0, 2.0, 7.0])
def test_eq12_solves_eq11(g):
    # Solve Eq. 11 (P_In + P_Re = P_Tr; P_In/Z_L - P_Re/Z_L = P_Tr/Z_R) with P_In = 1.
    z_l, z_r = 1.0, g
    a = np.array([[1.0, -1.0], [-1.0 / z_l, -1.0 / z_r]])
    b = np.array([-1.0, -1.0 / z_l])
    p_re, p_tr = np.linalg.solve(a, b)
    assert theory.pressure_transmission(g) == pytest.approx(p_tr, rel=1e-12)
    assert theory.pressure_reflection(g) == pytest.approx(p_re, abs=1e-12)
    # energy flux ~ P^2/Z: the coefficients are those fluxes and sum to 1
    assert theory.energy_transmission(g) == pytest.approx(p_tr**2 / z_r * z_l, rel=1e-12)
    assert theory.energy_reflection(g) == pytest.approx(p_re**2, abs=1e-12)
    assert theory.energy_transmission(g) + theory.energy_reflection(g) == pytest.approx(1.0)
    # velocity continuity: v_In + v_Re = v_Tr (Eq. 10b) with v = P/Z (right-going), -P/Z
    assert 1.0 + theory.velocity_reflection(g) == pytest.approx(
        theory.velocity_transmission(g), rel=1e-12)


def test_regions_and_points():
    assert theory.region(2.0, 0.5) == "I"
    assert theory.region(2.0, 2.0) == "II"
    assert theory.region(0.5, 2.0) == "III"
    assert theory.region(0.5, 0.5) == "IV"
    assert theory.region(1.0, 0.5) == "boundary gamma_c0=1"
    assert theory.region(1.0, 1.0) == "monodisperse"
    # the paper's points a-d (Fig. 5, 7) fall into I, III, IV, II
    expect = {"a": "I", "b": "III", "c": "IV", "d": "II"}
    for name, reg in expect.items():
        assert theory.predict(*theory.PAPER_POINTS[name]).region == reg
    # M, N, P, Q have the (gamma_c0, gamma_RG) of Fig. 8's caption
    gammas = {"M": (1, 0.5), "N": (1, 2), "P": (0.5, 1), "Q": (2, 1)}
    for name, (gc, gr) in gammas.items():
        p = theory.predict(*theory.PAPER_POINTS[name])
        assert (p.gamma_c0, p.gamma_RG) == pytest.approx((gc, gr), rel=1e-12)


def test_table2_prediction_limits():
    # With no linear part (no precompression) all ratios are the quadratic coefficients
    r = theory.table2_prediction(0.5, 1.0, 0.0, 1.0)
    assert r["Ep_tr"] == pytest.approx(theory.energy_transmission(0.5))
    # energy is conserved: tr + re = 1 for every kind
    r = theory.table2_prediction(0.5, 1.0, 10.0, 0.7)
    for kind in ("Ek", "Ep", "Et"):
        assert r[f"{kind}_tr"] + r[f"{kind}_re"] == pytest.approx(1.0, rel=1e-12)
    # a purely linear potential energy follows the displacement: 4/3 and -1/3 at M
    r = theory.table2_prediction(0.5, 0.0, 1.0, 0.0)
    assert (r["Ep_tr"], r["Ep_re"]) == pytest.approx((4 / 3, -1 / 3))


def test_validation_alpha():
    with pytest.raises(ValueError, match="alpha_rho"):
        theory.gamma_c0(0.0, 1.0)
    with pytest.raises(ValueError, match="alpha_kn"):
        theory.predict(1.0, -2.0)


def test_cli_theory_json(capsys):
    assert main(["theory", "--alpha-rho", "0.2", "--alpha-kn", "1", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("gamma_c0", "gamma_RG", "pressure_transmission", "energy_reflection",
                "energy_transmission", "region"):
        assert key in data
    assert data["region"] == "I"
    assert data["gamma_c0"] == pytest.approx(0.2**-0.5)


def test_cli_theory_table_and_errors(capsys):
    assert main(["theory", "--alpha-rho", "2", "--alpha-kn", "2.8284271247461903",
                 "--delta0", "1e-3"]) == 0
    out = capsys.readouterr().out
    assert "gamma_RG" in out and "c0_right_m_per_s" in out
    with pytest.raises(SystemExit):
        main(["theory", "--alpha-rho", "-1", "--alpha-kn", "1"])
    assert "alpha-rho" in capsys.readouterr().err


def test_fission_parameter_soliton_count():
    # On gamma_RG = 1 the amplitude is unchanged and q = gamma_c0 (Eq. 9).
    for gc in (0.5, 1.0, 2.0):
        a_r, a_k = theory.alphas_from_gammas(gc, 1.0)
        assert theory.fission_parameter(a_r, a_k) == pytest.approx(gc, rel=1e-12)
    # exactly one soliton at q = 1; lambda(lambda+1) = 2 q^2 binds ceil(lambda)
    a_r, a_k = theory.alphas_from_gammas(1.0, 1.0)
    assert theory.transmitted_soliton_count(a_r, a_k) == 1
    a_r, a_k = theory.alphas_from_gammas(2.0, 1.0)   # q = 2: lambda = 2.37 -> 3
    assert theory.transmitted_soliton_count(a_r, a_k) == 3
    # point N (gamma_c0 = 1, gamma_RG = 2): q = sqrt(4/3) > 1, a second soliton
    assert theory.fission_parameter(*theory.PAPER_POINTS["N"]) == pytest.approx(
        (4 / 3) ** 0.5, rel=1e-12)
    assert theory.predict(*theory.PAPER_POINTS["N"]).transmitted_solitons == 2
    # the KdV invariant behind q: l^2 * (A/xi0) is amplitude independent
    d, delta0 = 5e-3, 5e-6
    for amp in (1e-6, 1e-5):
        width = theory.kdv_soliton_width(amp, d, delta0)
        assert width**2 * amp / (delta0 / d) == pytest.approx(2 * d**2, rel=1e-12)


@pytest.mark.parametrize("a_r,a_k", [(1.0, 1.0), (0.3, 1.0), (3.0, 0.5), (0.8, 0.35),
                                     (2.0, 2.8284271247461903), (4.0, 0.25), (0.25, 4.0),
                                     (0.346, 0.36)])
def test_transmitted_effect_agrees_with_the_soliton_count(a_r, a_k):
    """The effect named for the transmitted wave is the fission parameter's: "fracture"
    exactly when more than one solitary wave is predicted (q > 1), naming the count; the
    paper's γ_c0 = 1 boundary stays in ``region``.  Steel | aluminium (γ_c0 > 1 but
    q < 1) once read "fracture" beside a count of one."""
    p = theory.predict(a_r, a_k)
    if p.fission_parameter > 1 + 1e-9:
        assert p.transmitted_effect.startswith("fracture")
        assert p.transmitted_solitons > 1 and f"{p.transmitted_solitons} solitary" in \
            p.transmitted_effect
    elif p.fission_parameter < 1 - 1e-9:
        assert p.transmitted_effect.startswith("squeeze") and p.transmitted_solitons == 1
    else:
        assert "boundary" in p.transmitted_effect and p.transmitted_solitons == 1
