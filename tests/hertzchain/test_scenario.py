"""Scenario validation: every class of bad input gets one clear error."""

from importlib.resources import files

import pytest

from hertzchain.scenario import ScenarioError, load_scenario, parse_scenario


def base():
    return {
        "chain": {"delta0_over_d": 1e-3, "sections": [{"n": 200}, {"n": 200, "alpha_rho": 2}]},
        "initial": {"kind": "cut_wave", "center": 100},
        "run": {"t_end": 1e-3},
        "record": {"energy_every": 10},
    }


def test_base_is_valid():
    sc = parse_scenario(base())
    assert sc.chain.n == 400
    assert sc.chain.sections[1].alpha_rho == 2.0
    assert sc.run.dt is None
    assert sc.to_dict()["chain"]["sections"][0]["n"] == 200


@pytest.mark.parametrize("name", ["table2_M.toml", "impact_sonic_vacuum.toml",
                                  "mass_mismatch.toml"])
def test_shipped_examples_are_valid(name):
    sc = load_scenario(files("hertzchain") / "scenarios" / name)
    assert sc.chain.n >= 2


def _with(path, value):
    d = base()
    node = d
    for key in path[:-1]:
        node = node[key]
    if value is _DELETE:
        node.pop(path[-1])
    else:
        node[path[-1]] = value
    return d


_DELETE = object()

BAD = [
    (("chain", "delta0_ovr_d"), 1e-3, "unknown key"),                 # typo
    (("chain", "sections"), [], "sections is required"),
    (("chain", "sections"), [{"n": 0}], "n = 0 must be >= 1"),
    (("chain", "sections"), [{"n": 1}], ">= 2 grains"),
    (("chain", "sections"), [{"n": 2.5}], "must be an integer"),
    (("chain", "sections"), [{"n": 100}, {"n": 100, "alpha_rho": 0}], "alpha_rho"),
    (("chain", "sections"), [{"n": 100}, {"n": 100, "alpha_kn": -5}], "alpha_kn"),
    (("chain", "sections"), [{"n": 100}, {"n": 100, "alpha_kn": float("nan")}], "finite"),
    (("chain", "sections"), [{"n": 100}, {"n": 100, "alpha_kn": float("inf")}], "finite"),
    (("chain", "sections"), [{"n": 100, "alpha_rho": "heavy"}], "must be a number"),
    (("chain", "sections"), [{"n": 100, "colour": "red"}], "unknown key"),
    (("chain", "sections"), [{"n": 300, "material": {"density": 7900,
                                                      "youngs_modulus": 2e11,
                                                      "poisson_ratio": 0.7}}], "poisson_ratio"),
    (("chain", "sections"), [{"n": 300, "material": {"density": -1,
                                                      "youngs_modulus": 2e11,
                                                      "poisson_ratio": 0.3}}], "density"),
    (("chain", "sections"), [{"n": 300, "material": "unobtainium"}], "material"),
    (("chain", "sections"), [{"n": 300, "material": "paper", "alpha_rho": 2}], "either"),
    (("chain", "diameter"), -5e-3, "diameter"),
    (("chain", "delta0_over_d"), -1e-3, "delta0_over_d"),
    (("chain", "delta0_over_d"), 0.5, "delta0_over_d"),
    (("chain", "left_wall"), "sticky", "left_wall"),
    (("chain", "right_wall"), "free", "needs two walls"),
    (("initial", "kind"), "explosion", "kind"),
    (("initial", "center"), 399, "outside the chain"),
    (("initial", "center"), _DELETE, "center is required"),
    (("initial", "half_width"), 10, "half_width"),
    (("initial", "v0"), 0, "v0"),
    (("run", "t_end"), _DELETE, "t_end"),
    (("run", "t_end"), -1.0, "t_end"),
    (("run", "dt"), 0.0, "dt"),
    (("run", "dt"), "fast", "must be a number"),
    (("run", "until_front_at"), 400, "can never be reached"),
    (("run", "max_steps"), 0, "max_steps"),
    (("record", "snapshot_times"), [2e-3], "t_end"),
    (("record", "time_series_grains"), [400], "time_series_grains"),
    (("record", "running_max"), "yes", "running_max"),
    (("record", "energy_every"), -1, "energy_every"),
]


@pytest.mark.parametrize(("path", "value", "message"), BAD)
def test_bad_input_is_named(path, value, message):
    with pytest.raises(ScenarioError, match=message):
        parse_scenario(_with(path, value))


def test_exact_wave_needs_amplitude():
    d = base()
    d["initial"] = {"kind": "exact_wave", "center": 100}
    with pytest.raises(ScenarioError, match="velocity_max"):
        parse_scenario(d)


def test_load_errors(tmp_path):
    with pytest.raises(ScenarioError, match="not found"):
        load_scenario(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[chain\n")
    with pytest.raises(ScenarioError, match="not valid TOML"):
        load_scenario(bad)
    typo = tmp_path / "typo.toml"
    typo.write_text("[chian]\n")
    with pytest.raises(ScenarioError, match=r"typo.toml: unknown table \[chian\]; did you "
                                            r"mean \[chain\]\?"):
        load_scenario(typo)


EXACT_WAVE_N2 = """name = "exact_wave_n2_precompressed"
[chain]
exponent = 2.0
delta0_over_d = 1e-3
[[chain.sections]]
n = 120
[initial]
kind = "exact_wave"
center = 30
strain_max = 5e-4
[run]
until_front_at = 90
[models]
theory = false
"""


def test_exact_wave_of_a_precompressed_power_law_runs(tmp_path, capsys):
    # kind = "exact_wave" with exponent 2 and δ0/d = 1e-3 (the exact wave of any power law
    # with precompression: theory.discrete_solitary_wave(exponent=n)): `hertzchain run`
    # completes, and the wave keeps the exact wave's speed, 8 % above c0 (front speed
    # measured 1.5e-6 from it; tolerance 1e-5), energy drift 5.9e-9 (tolerance 1e-7).
    import json

    import theory
    from hertzchain.cli import main
    from hertzchain.runner import build_chain

    path = tmp_path / "ew.toml"
    path.write_text(EXACT_WAVE_N2)
    assert main(["run", str(path), "--json", "--no-progress"]) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["completed"] and summary["energy_drift"] < 1e-7
    ch = build_chain(load_scenario(path).chain)
    w = theory.discrete_solitary_wave(ch.k[5], ch.mass[5], ch.diameter[5], ch.delta0[5],
                                      amplitude=5e-4 * ch.diameter[5], exponent=2.0)
    assert summary["front_speed_tr"] == pytest.approx(w.speed, rel=1e-5)
    assert w.speed > 1.05 * theory.c0(ch.k[5], ch.mass[5], ch.diameter[5], ch.delta0[5],
                                      exponent=2.0)
