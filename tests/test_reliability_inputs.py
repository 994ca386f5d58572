"""Extreme but valid-looking inputs: a correct result or an error naming the parameter.

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


# -- item 12: valid-looking scenarios --------------------------------------------------
def _data(**changes):
    data = {"chain": {"sections": [{"n": 60}, {"n": 60}]}, "initial": {"kind": "impact"},
            "run": {"t_end": 4e-4, "max_steps": 100_000}}
    for path, value in changes.items():
        node = data
        keys = path.split("__")
        for key in keys[:-1]:
            node = node[int(key)] if key.isdigit() else node[key]
        node[keys[-1]] = value
    return data


EXTREME_SCENARIOS = {
    # case: (changes, the key a rejection must name, or None if it must run and complete)
    "alpha_rho=1e-300": ({"chain__sections__1__alpha_rho": 1e-300}, "alpha_rho"),
    "alpha_kn=1e300": ({"chain__sections__1__alpha_kn": 1e300}, "alpha_kn"),
    "alpha_rho=1e300": ({"chain__sections__1__alpha_rho": 1e300}, None),
    "diameter=1e-30": ({"chain__diameter": 1e-30, "run__max_steps": 10}, "max_steps"),
    "t_end=1e300": ({"run__t_end": 1e300, "run__max_steps": 10}, "max_steps"),
    "n=1e12": ({"chain__sections__0__n": 10**12}, "[chain.sections] n"),
    "v0=1e-300": ({"initial__v0": 1e-300}, "[initial] v0"),
    "delta0=1e-140": ({"chain__delta0_over_d": 1e-140}, None),
    "delta0=5e-324": ({"chain__delta0_over_d": 5e-324}, None),
}


@pytest.mark.parametrize("case", sorted(EXTREME_SCENARIOS))
def test_extreme_scenarios_run_or_name_the_key(case):
    from hertzchain.runner import run_scenario
    from hertzchain.scenario import ScenarioError, parse_scenario

    changes, key = EXTREME_SCENARIOS[case]
    if key is None:
        summary = run_scenario(parse_scenario(_data(**changes)))
        assert summary["completed"] and summary["stopped_by"] == "t_end"
        assert math.isfinite(summary["energy_drift"]) and summary["energy_drift"] < 1e-4
        return
    with pytest.raises(ScenarioError) as exc:
        run_scenario(parse_scenario(_data(**changes)))
    assert key in str(exc.value), str(exc.value)


def test_tiny_precompression_runs_like_none():
    """δ0/d = 1e-140 was an InstabilityError blaming dt: U(δ0) underflowed to 0 and
    expm1(2.5 log1p((r - δ0)/δ0)) overflowed, 0·inf = NaN in the energy rows."""
    from hertzchain.runner import run_scenario
    from hertzchain.scenario import parse_scenario

    tiny = run_scenario(parse_scenario(_data(chain__delta0_over_d=1e-140)))
    none = run_scenario(parse_scenario(_data()))
    assert tiny["steps"] == none["steps"]
    assert tiny["energy_drift"] == pytest.approx(none["energy_drift"], rel=1e-6)


@pytest.mark.parametrize("d0", [1e-3, 1e-125, 1e-140, 1e-300, 5e-324])
def test_wave_energy_finite_for_tiny_precompression(d0):
    """Contact energy U(r) - U(δ0) (J) of the law, its NumPy twin and the theory's."""
    k, r = 1e10, np.array([1e-6, 3e-6, 1e-9])
    exact = 0.4 * k * (r**2.5 - d0**2.5)
    got = [theory.wave_contact_energy(r, k, d0), theory.laws.HERTZ.energy(r, k, d0)]
    for e in got:
        assert np.all(np.isfinite(e))
        np.testing.assert_allclose(e, exact, rtol=1e-12)


def test_kernel_energy_finite_for_tiny_precompression():
    from discrete import Chain, Simulation
    from discrete.initial import impact

    ch = Chain.two_section(40, 0, delta0_over_d=1e-140)
    init = impact(ch, 1.0)
    sim = Simulation(ch, init.u, init.v)
    sim.run(t_end=1e-4)
    assert np.isfinite(sim.energy_drift) and sim.energy_drift < 1e-4


def test_deeply_nested_toml_names_the_file(tmp_path):
    from hertzchain.scenario import ScenarioError, load_scenario

    path = tmp_path / "deep.toml"
    path.write_text("x = " + "[" * 5000 + "]" * 5000 + "\n")
    with pytest.raises(ScenarioError, match="deep.toml.*nested too deeply"):
        load_scenario(path)


def test_non_utf8_scenario_names_the_file(tmp_path, capsys):
    from hertzchain.scenario import ScenarioError, load_scenario

    path = tmp_path / "latin1.toml"
    path.write_bytes('name = "Müller"\n[[chain.sections]]\nn = 10\n'.encode("latin-1"))
    with pytest.raises(ScenarioError, match=r"latin1\.toml: not UTF-8.*offset 9"):
        load_scenario(path)
    assert main(["run", str(path)]) == 2
    assert "latin1.toml: not UTF-8" in capsys.readouterr().err


def test_directory_as_scenario_names_it(tmp_path):
    from hertzchain.scenario import ScenarioError, load_scenario

    with pytest.raises(ScenarioError, match="is a directory"):
        load_scenario(tmp_path)
