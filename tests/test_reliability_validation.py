"""Every public entry point rejects bad input with one clear error naming the field.

Beyond the TOML cases of ``tests/hertzchain/test_scenario.py``: the Python API (chains,
materials, Simulation and its run, recording, initial conditions, theory functions), the
checks of the runner that need the built chain (dt above the stability bound, a stop
event the wave can never reach, a chain too short for the wave, a wave across an
interface, a non-physical amplitude or section stiffness) and the CLI flags.  Each case
asserts the exception type and that the parameter's name appears in the message (and,
where the check has a range, the allowed range).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import discrete
import theory
from discrete import Chain, Recording, Section, Simulation, WaveAt
from discrete.initial import cut_wave, exact_wave, impact
from hertzchain.cli import main
from hertzchain.runner import run_scenario
from hertzchain.scenario import ScenarioError, parse_scenario

NAN, INF = math.nan, math.inf


def _chain(n=50, delta0_over_d=0.0):
    return Chain.two_section(n, 0, delta0_over_d=delta0_over_d)


def _sim(**kw):
    ch = _chain()
    init = impact(ch, 1.0)
    return Simulation(ch, init.u, init.v, **kw)


API = {
    # chains
    "mass<0": (lambda: Chain.from_arrays([1.0, -1.0], [1e9] * 3), "mass"),
    "mass nan": (lambda: Chain.from_arrays([1.0, NAN], [1e9] * 3), "mass"),
    "k inf": (lambda: Chain.from_arrays([1.0, 1.0], [1e9, INF, 1e9]), "k"),
    "delta0<0": (lambda: Chain.from_arrays([1.0, 1.0], [1e9] * 3, -1e-6), "delta0"),
    "one grain": (lambda: Chain.from_arrays([1.0], [1e9] * 2), "N >= 2"),
    "alpha_rho=0": (lambda: Chain.two_section(10, 10, alpha_rho=0.0), "alpha_rho"),
    "alpha_kn<0": (lambda: Chain.two_section(10, 10, alpha_kn=-1.0), "alpha_kn"),
    "alpha_rho nan": (lambda: Chain.two_section(10, 10, alpha_rho=NAN), "alpha_rho"),
    "delta0_over_d<0": (lambda: Chain.two_section(10, 10, delta0_over_d=-1e-3),
                        "delta0_over_d"),
    "diameter inf": (lambda: Chain.two_section(10, 10, diameter=INF), "diameter"),
    "n_left=0": (lambda: Chain.two_section(0, 10), "n_left"),
    "Section.n=0": (lambda: Section(0, 5e-3, theory.PAPER_MATERIAL), "Section.n"),
    # materials
    "density<0": (lambda: theory.Material(-1.0, 2e11, 0.3), "density"),
    "poisson 0.5": (lambda: theory.Material(7900.0, 2e11, 0.5), "poisson_ratio"),
    "youngs nan": (lambda: theory.Material(7900.0, NAN, 0.3), "youngs_modulus"),
    # Simulation and run
    "dt<0": (lambda: _sim(dt=-1e-8), "dt"),
    "dt nan": (lambda: _sim(dt=NAN), "dt"),
    "u nan": (lambda: Simulation(_chain(), u=np.full(50, NAN)), "u"),
    "v shape": (lambda: Simulation(_chain(), v=np.zeros(49)), "v"),
    "wall inf": (lambda: _sim(wall_left=INF), "wall_left"),
    "drift_tolerance=0": (lambda: _sim(drift_tolerance=0.0), "drift_tolerance"),
    "chunk=0": (lambda: _sim(chunk=0), "chunk"),
    "run t_end nan": (lambda: _sim().run(NAN), "t_end"),
    "run max_steps<0": (lambda: _sim().run(max_steps=-1), "max_steps"),
    "run nothing": (lambda: _sim().run(), "t_end"),
    # recording
    "series grain": (lambda: _sim(record=Recording(series_grains=[50])), "series grain"),
    "energy_every=0": (lambda: _sim(record=Recording(energy_every=0)), "energy_every"),
    "WaveAt outside": (lambda: _sim(record=Recording(snapshots=[WaveAt(50)])),
                       "WaveAt grain"),
    "WaveAt threshold": (lambda: _sim().run(until=WaveAt(10, threshold=-1.0)), "threshold"),
    # initial conditions
    "impact v0 nan": (lambda: impact(_chain(), NAN), "v0"),
    "striker_mass<0": (lambda: impact(_chain(), 1.0, striker_mass=-1.0), "striker_mass"),
    "cut_wave centre": (lambda: cut_wave(_chain(), 80), "centre"),
    "exact_wave centre": (lambda: exact_wave(_chain(100, 1e-3), 500.0, velocity_max=0.08),
                          "centre"),
    "chain too short": (lambda: exact_wave(_chain(100, 1e-3), 50.0, velocity_max=0.0822),
                        "centre"),
    "velocity_max<0": (lambda: exact_wave(_chain(300, 1e-3), 150.0, velocity_max=-1.0),
                       "velocity_max"),
    "default_dt at rest": (lambda: discrete.default_dt(_chain()), "dt"),
    # theory
    "c0 k_n<0": (lambda: theory.c0(-1.0, 1e-3, 5e-3, 5e-6), "k_n"),
    "gamma_c0 alpha_rho=0": (lambda: theory.gamma_c0(0.0, 1.0), "alpha_rho"),
    "grain_mass nan": (lambda: theory.grain_mass(NAN, 7900.0), "diameter"),
    "nesterenko nan": (lambda: theory.nesterenko_speed(NAN, 0.0, 0.1), "c_mat"),
    "predict inf": (lambda: theory.predict(INF, 1.0), "alpha_rho"),
    "kdv xi_max<0": (lambda: theory.kdv_speed(1.0, 5e-3, 5e-6, -1.0), "xi_max"),
    "static_overlaps k<0": (lambda: theory.static_overlaps([1.0, -1.0], delta0=1e-6),
                            "k_contacts"),
}


@pytest.mark.parametrize("case", sorted(API))
def test_python_api_rejects_bad_input(case):
    func, name = API[case]
    with pytest.raises(ValueError) as err:
        func()
    assert name in str(err.value)


def _scenario(**over):
    d = {"chain": {"delta0_over_d": 1e-3, "sections": [{"n": 150}, {"n": 200}]},
         "initial": {"kind": "exact_wave", "center": 75, "velocity_max": 0.0822},
         "run": {"t_end": 5e-4}}
    for table, values in over.items():
        d[table] = {**d.get(table, {}), **values}
    return d


RUNNER = {
    # dt above the stability bound: the bound and 'auto' are named with the range
    "dt above stable": (_scenario(run={"dt": 1e-4}),
                        r"\[run\] dt = 0.0001 s is above the largest linearly stable .*"
                        r"allowed range \(0, "),
    # a stop event the wave can never reach (behind a right-going wave)
    "until behind the wave": (_scenario(run={"until_front_at": 40}),
                              r"\[run\] until_front_at = 40 can never be reached.*"
                              r"allowed range \[76, 349\]"),
    # the requested wave is wider than the chain (tails reach the wall)
    "chain too short": (_scenario(chain={"sections": [{"n": 100}]},
                                  initial={"center": 50}),
                        r"\[initial\] center = 50 .*does not fit"),
    # the wave straddles the interface
    "wave across interface": (_scenario(chain={"sections": [{"n": 100}, {"n": 250,
                                                                          "alpha_kn": 2.0}]},
                                        initial={"center": 85}),
                              r"\[initial\] center = 85 .*one section"),
    # non-physical amplitudes (overlap beyond the Hertz small-strain range)
    "impact v0 huge": ({**_scenario(), "initial": {"kind": "impact", "v0": 1e4}},
                       r"\[initial\] v0 = 10000.0 m/s is non-physical.*allowed < 0.1"),
    "exact velocity_max huge": (_scenario(initial={"velocity_max": 1e3}),
                                r"\[initial\] velocity_max = 1000.0 .*non-physical"),
    # a section so soft that its static overlap exceeds half a diameter
    "alpha_kn tiny": (_scenario(chain={"sections": [{"n": 150}, {"n": 200,
                                                                 "alpha_kn": 1e-6}]}),
                      r"\[chain\] non-physical chain: delta0 .*alpha_kn"),
}


@pytest.mark.parametrize("case", sorted(RUNNER))
def test_runner_rejects_what_needs_the_built_chain(case):
    d, message = RUNNER[case]
    sc = parse_scenario(d)  # valid as a table...
    with pytest.raises(ScenarioError, match=message):
        run_scenario(sc)  # ...but not for this chain


def test_runner_rejects_bad_checkpoint_interval():
    with pytest.raises(ValueError, match="checkpoint_interval"):
        run_scenario(parse_scenario(_scenario()), checkpoint_interval=-1.0)


CLI = {
    "interval<0": (["run", "X.toml", "--checkpoint-interval", "-1"], "--checkpoint-interval"),
    "interval nan": (["run", "X.toml", "--checkpoint-interval", "nan"],
                     "--checkpoint-interval"),
    "threads=0": (["run", "X.toml", "--threads", "0"], "--threads"),
    "alpha-rho=0": (["theory", "--alpha-rho", "0", "--alpha-kn", "1"], "--alpha-rho"),
    "alpha-kn nan": (["theory", "--alpha-rho", "1", "--alpha-kn", "nan"], "--alpha-kn"),
    "delta0<0": (["theory", "--alpha-rho", "1", "--alpha-kn", "1", "--delta0", "-1"],
                 "--delta0"),
}


@pytest.mark.parametrize("case", sorted(CLI))
def test_cli_flags_are_validated(case, capsys):
    argv, flag = CLI[case]
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert flag in err and ("must be" in err or "expected" in err)


def test_cli_run_bad_files(tmp_path, capsys):
    assert main(["run", str(tmp_path / "missing.toml")]) == 2
    assert "scenario file not found" in capsys.readouterr().err
    typo = tmp_path / "typo.toml"
    typo.write_text('[chain]\ndiamter = 5e-3\n[[chain.sections]]\nn = 10\n[run]\nt_end = 1e-4\n')
    assert main(["run", str(typo)]) == 2
    assert ("unknown key 'diamter' in [chain]; did you mean 'diameter'?"
            in capsys.readouterr().err)
    dt = tmp_path / "dt.toml"
    dt.write_text('[chain]\n[[chain.sections]]\nn = 40\n[run]\nt_end = 1e-4\ndt = 1e-3\n')
    assert main(["run", str(dt)]) == 2
    assert "[run] dt = 0.001 s is above the largest linearly stable" in capsys.readouterr().err
