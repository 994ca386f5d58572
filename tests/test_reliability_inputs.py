"""Extreme but valid-looking inputs: a correct result or an error naming the parameter (issue 14).

Item 5: ``hertzchain theory`` printed ``transmitted_solitons -9223372036854775808`` for
extreme ratios (an int64 cast of a huge λ) and took any ``--delta0``; item 12: inputs
that pass the schema crashed deep inside (ZeroDivisionError, MemoryError,
RecursionError, UnicodeDecodeError) or blamed the wrong key.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import theory
from hertzchain.cli import main
from hertzchain.scenario import schema_key

EXTREMES = [1e-300, 1e-200, 1e-31, 1e-3, 1.0, 1e3, 1e31, 1e200, 1e300, 5e-324, 1.7e308]


# -- item 5: the theory ----------------------------------------------------------------
@pytest.mark.parametrize("alpha_kn", EXTREMES)
@pytest.mark.parametrize("alpha_rho", EXTREMES)
def test_soliton_count_is_correct_or_names_the_ratios(alpha_rho, alpha_kn):
    q = theory.fission_parameter(alpha_rho, alpha_kn)
    assert math.isfinite(q) and q > 0
    lam = (math.sqrt(1 + 8 * q * q) - 1) / 2 if q < 1e100 else math.sqrt(2) * q
    try:
        count = theory.transmitted_soliton_count(alpha_rho, alpha_kn)
    except ValueError as exc:
        assert "alpha_rho" in str(exc) and "alpha_kn" in str(exc)
        assert lam >= 0.99 * theory.MAX_SOLITON_COUNT
        return
    assert isinstance(count, int)
    assert count >= 1  # a positive sech² well binds at least one soliton
    assert count - 1 <= lam * (1 + 1e-9) + 1e-9 and lam <= count * (1 + 1e-9) + 1e-9
    coeff = theory.energy_transmission(theory.gamma_rg(alpha_rho, alpha_kn))
    assert 0 <= coeff <= 1


def test_soliton_count_tiny_q_is_one_and_array_form():
    # q = 1.4e-150: λ ≈ 4e-300; the old ceil(λ - 1e-9) said 0 solitons
    assert theory.transmitted_soliton_count(1e300, 1.0) == 1
    counts = theory.transmitted_soliton_count(np.array([1e300, 1.0, 1e-30]), 1.0)
    assert counts.dtype == np.int64 and list(counts[:2]) == [1, 1] and counts[2] > 1e7
    with pytest.raises(ValueError, match="alpha_rho"):
        theory.transmitted_soliton_count(np.array([1.0, 1e-300]), 1.0)


def test_energy_transmission_does_not_underflow_to_zero_by_overflow():
    g = 1e200  # (1 + g)² overflowed to inf: 4g/inf = 0 instead of 4e-200
    assert theory.energy_transmission(g) == pytest.approx(4e-200, rel=1e-12)


@pytest.mark.parametrize(("alpha_rho", "alpha_kn"), [(1e-300, 1.0), (1.0, 1e300),
                                                     (1e-200, 1e200), (1e-308, 1e308)])
def test_cli_theory_extreme_ratios_never_print_garbage(alpha_rho, alpha_kn, capsys):
    code = main(["theory", "--alpha-rho", repr(alpha_rho), "--alpha-kn", repr(alpha_kn),
                 "--json"])
    out, err = capsys.readouterr()
    if code == 0:
        assert json.loads(out)["transmitted_solitons"] >= 1
    else:
        assert code == 2 and "alpha_rho" in err and "-922" not in out + err


def test_cli_theory_moderate_ratios_still_count(capsys):
    assert main(["theory", "--alpha-rho", "1e-20", "--alpha-kn", "1", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["transmitted_solitons"] == math.ceil(
        (math.sqrt(1 + 8 * theory.fission_parameter(1e-20, 1.0) ** 2) - 1) / 2 - 1e-9)


@pytest.mark.parametrize("value", ["1e300", "0.1", "0.5"])
def test_cli_theory_delta0_has_the_scenario_bound(value, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["theory", "--alpha-rho", "1", "--alpha-kn", "1", "--delta0", value])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    key = schema_key("chain", "delta0_over_d")  # the one definition of the bound
    assert "--delta0" in err and key.range_text() in err and "delta0_over_d" in err


def test_cli_theory_delta0_below_the_bound_runs(capsys):
    high = schema_key("chain", "delta0_over_d").high
    assert main(["theory", "--alpha-rho", "1", "--alpha-kn", "1", "--delta0",
                 repr(0.99 * high), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert 0 < out["c0_left_m_per_s"] < 1e5  # m/s: a steel chain's, not 5e78
