"""A stated accuracy (``rtol``): the step-doubling estimate bounds the true error.

The true error of the recorded quantities is measured against the same run at a step
16 times smaller (velocity Verlet, second order: its own error is then ~1/256 of the
run's, far below the tolerances here).  The quantities are those the probe compares
(:func:`discrete.timestep.probe_error`): every grain's running maximum of v whose peak
has passed, over the largest |v|.  Reduced sizes (200-300 grains); the estimate must
bound the true error, and must not overstate it by more than a factor 50 (else rtol
would buy nothing).
"""

import math

import numpy as np
import pytest

import theory
from discrete import Chain, Section, Simulation, TimeStep
from discrete.initial import exact_wave, impact
from discrete.timestep import probe_error

MAT = theory.PAPER_MATERIAL
D = 5e-3


def _true_error(init, step: TimeStep, t_end: float) -> float:
    """max over grains of |v̄max - v̄max_ref| / max|v̄max_ref| (peaks passed), relative."""
    runs = []
    for dt, method in ((step.dt, step.integrator), (step.dt / 16, "verlet")):
        sim = init.simulation(dt=dt, integrator=method)
        sim.run(t_end, progress=False)
        runs.append((np.array(sim.record.vmax), sim.v.copy()))
    (vm, _), (ref, vref) = runs
    scale = float(np.max(np.abs(ref)))
    done = (vref < 0.5 * ref) & (ref > 0.01 * scale)
    assert done.sum() >= 20  # the comparison covers the wave's path
    return float(np.max(np.abs(vm[done] - ref[done]))) / scale


def _impact():
    chain = Chain.from_sections([Section(250, D, MAT)], delta0=0.0)
    return impact(chain, 1.0), 1.6e-3  # the wave reaches grain ~200


def _solitary():
    chain = Chain.from_sections([Section(300, D, MAT)], delta0=1e-3 * D,
                                left_wall="paper", right_wall="paper")
    return exact_wave(chain, 40, strain_max=5e-4), 8e-4


def _interface():
    soft = MAT.scaled(1.0, 0.3)
    chain = Chain.from_sections([Section(120, D, MAT), Section(150, D, soft)], delta0=0.0)
    return impact(chain, 1.0), 1.6e-3  # through the interface at grain 120


@pytest.mark.parametrize("rtol", [1e-3, 1e-4])
@pytest.mark.parametrize("problem", [_impact, _solitary, _interface],
                         ids=["impact", "solitary_precompressed", "interface"])
def test_estimate_bounds_true_error(problem, rtol):
    init, t_end = problem()
    step = TimeStep.choose(init.chain, init.u, init.v, init.wall_left, init.wall_right,
                           rtol=rtol, horizon=t_end)
    assert step.source == "rtol" and step.rtol == rtol
    assert step.error_estimate <= rtol * (1 + 1e-9)  # aimed at rtol (to rounding)
    assert step.dt <= step.stable
    true = _true_error(init, step, t_end)
    assert true <= step.error_estimate, (true, step.error_estimate, step.order)
    assert true >= step.error_estimate / 50, (true, step.error_estimate)


def test_auto_integrator_is_the_cheaper_and_bounded():
    """integrator=None probes Verlet and Yoshida-4; the choice meets rtol too."""
    init, t_end = _solitary()
    step = TimeStep.choose(init.chain, init.u, init.v, init.wall_left, init.wall_right,
                           rtol=1e-4, integrator=None, horizon=t_end)
    assert step.integrator in ("verlet", "yoshida4")
    assert _true_error(init, step, t_end) <= step.error_estimate


def test_probe_observes_second_order_for_sampled_maxima():
    """The running maxima are sampled once per step: the probe sees order ~2 for Verlet."""
    init, _ = _impact()
    pr = probe_error(init.chain, init.u, init.v, integrator="verlet")
    assert 1.0 <= pr["order"] <= 2.0
    assert pr["error_q"] > 0 and pr["probe_steps"] > 0


def test_explicit_dt_wins_and_bad_rtol():
    init, _ = _impact()
    step = TimeStep.choose(init.chain, init.u, init.v, dt=1e-8, rtol=1e-4)
    assert step.source == "explicit" and step.dt == 1e-8 and math.isnan(step.error_estimate)
    for bad in (0.0, 1.0, -1e-3, float("nan"), True, "1e-4"):
        with pytest.raises(ValueError, match="rtol"):
            TimeStep.choose(init.chain, init.u, init.v, rtol=bad)
    with pytest.raises(ValueError, match="needs rtol"):
        TimeStep.choose(init.chain, init.u, init.v, integrator=None)


def test_simulation_rtol_keeps_estimate_through_save(tmp_path):
    from discrete import load, save

    init, _ = _impact()
    sim = Simulation(init.chain, init.u, init.v, rtol=1e-4, integrator="auto")
    sim.run(2e-4, progress=False)
    assert sim.time_step.source == "rtol" and sim.time_step.error_estimate <= 1e-4
    save(tmp_path / "r.h5", sim)
    back = load(tmp_path / "r.h5")
    assert back.time_step.error_estimate == sim.time_step.error_estimate
    assert back.time_step.rtol == 1e-4 and back.integrator == sim.integrator


def _scenario(**run):
    from hertzchain.scenario import parse_scenario

    return parse_scenario({"name": "rtol", "chain": {"sections": [{"n": 120}]},
                           "initial": {"kind": "impact", "v0": 1.0},
                           "run": {"until_front_at": 80, **run}})


def test_scenario_rtol_summary_and_errors():
    from hertzchain.runner import run_simulation
    from hertzchain.scenario import ScenarioError

    summary, sim = run_simulation(_scenario(rtol=1e-4, integrator="auto"))
    assert summary["dt_source"] == "rtol" and summary["rtol"] == 1e-4
    assert 0 < summary["rtol_estimate"] <= 1e-4 * (1 + 1e-9)
    assert summary["integrator"] == sim.integrator in ("verlet", "yoshida4")
    plain, _ = run_simulation(_scenario())
    assert plain["dt_source"] == "default" and plain["rtol"] is None
    with pytest.raises(ScenarioError, match="needs rtol"):
        _scenario(integrator="auto")
    with pytest.raises(ScenarioError, match="rtol"):
        _scenario(rtol=1e-4, dt_fraction=0.01)
    with pytest.raises(ScenarioError, match="rtol"):
        _scenario(rtol=2.0)


def test_cli_rtol(tmp_path, capsys):
    import json

    from hertzchain.cli import main

    path = tmp_path / "s.toml"
    path.write_text('name = "s"\n[chain]\n[[chain.sections]]\nn = 120\n[initial]\n'
                    'kind = "impact"\n[run]\nuntil_front_at = 80\n')
    assert main(["run", str(path), "--json", "--rtol", "1e-3"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["dt_source"] == "rtol" and out["rtol"] == 1e-3


def test_rtol_with_damping_takes_verlet():
    from discrete import ViscoelasticHertz

    init, _ = _impact()
    law = ViscoelasticHertz(damping_time=1e-7)
    step = TimeStep.choose(init.chain, init.u, init.v, rtol=1e-3, integrator=None, law=law)
    assert step.integrator == "verlet" and step.error_estimate <= 1e-3 * (1 + 1e-9)
