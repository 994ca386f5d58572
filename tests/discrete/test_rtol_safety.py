"""The rtol step rule's safety factor, its step search, and which maxima it is about.

The step is the largest h <= h_max with (E(h) + F(h))/s <= rtol (discrete.timestep):
s is 0.6 where every compared quantity is smooth in h (refined maxima), 0.5 where one
is sampled once per step; the search must find the largest such step (checked against a
brute-force scan of the same estimate); the chosen step says which running maxima its
estimate is about (``TimeStep.maxima``, the summary's ``rtol_maxima``), and those are
the maxima the run keeps.
"""

import math

import numpy as np
import pytest

import theory
from discrete import Chain, Recording, Section, Simulation, TimeStep, ViscoelasticHertz
from discrete.initial import impact
from discrete.timestep import (
    RTOL_SAFETY,
    RTOL_SAFETY_REFINED,
    _rtol_step,
    probe_error,
    rtol_safety,
)

D = 5e-3


def _impact(n=150):
    chain = Chain.from_sections([Section(n, D, theory.PAPER_MATERIAL)], delta0=0.0)
    return impact(chain, 1.0)


@pytest.mark.parametrize(("recording", "velocity_dependent", "safety"), [
    (None, False, RTOL_SAFETY_REFINED),
    (Recording(maxima=True), False, RTOL_SAFETY_REFINED),
    (Recording(maxima=True), True, RTOL_SAFETY),  # dissipative: sampled maxima
    (Recording(maxima=True, refined_maxima=False), False, RTOL_SAFETY),
    (Recording(maxima=True, strain_maxima=True), False, RTOL_SAFETY),  # overlaps sampled
    (Recording(maxima=True, series_grains=[3]), False, RTOL_SAFETY),  # contact times
])
def test_safety_follows_the_compared_quantities(recording, velocity_dependent, safety):
    assert rtol_safety(recording, velocity_dependent) == safety
    assert rtol_safety(recording, velocity_dependent, energy_ratios=True) == RTOL_SAFETY
    assert 0 < RTOL_SAFETY < RTOL_SAFETY_REFINED < 1


def test_step_search_finds_the_largest_step_meeting_rtol():
    """Against a brute-force scan from h_max down: with a long horizon the round-off
    floor F takes a share of the budget (the search starts below the step where E alone
    meets s·rtol); the step found meets rtol and no step between it and h_max does."""
    init = _impact()
    pr = probe_error(init.chain, init.u, init.v, integrator="verlet", horizon=2e-4)
    h_max = pr.h0
    for horizon in (2e-4, 3e2):  # F negligible; F a large share
        def est(h, horizon=horizon):
            return (pr.error_at(h) + pr.roundoff_at(h, horizon)) / RTOL_SAFETY_REFINED

        grid = h_max * 2.0 ** (-np.arange(16 * 40 + 1) / 16.0)
        ests = np.array([est(x) for x in grid])
        rtol = float(2.0 * np.min(ests))  # met on an interval of steps
        h, e = _rtol_step(pr, rtol, h_max, horizon, RTOL_SAFETY_REFINED)
        assert h is not None and e == pytest.approx(est(h), rel=1e-12) and e <= rtol
        # the brute-force scan's largest grid step that meets rtol is at or below h, and
        # the grid step above h (if any) does not meet it
        first = int(np.flatnonzero(ests <= rtol)[0])
        assert grid[first] <= h * (1 + 1e-12)
        above = grid[grid > h * (1 + 1e-9)]
        assert above.size == 0 or est(float(above[-1])) > rtol
        # unreachable: below the smallest estimate of the scan
        none, least = _rtol_step(pr, 0.5 * float(np.min(ests)), h_max, horizon,
                                 RTOL_SAFETY_REFINED)
        assert none is None and least >= 0.5 * float(np.min(ests))


def test_time_step_says_which_maxima_and_the_run_keeps_them():
    init = _impact()
    args = (init.chain, init.u, init.v)
    plain = TimeStep.choose(*args)
    assert plain.maxima is None and plain.to_dict()["rtol_maxima"] == ""
    step = TimeStep.choose(*args, rtol=1e-3, horizon=2e-4)
    assert step.maxima == "refined"
    sim = Simulation(init.chain, init.u, init.v, dt=step, record=Recording(maxima=True))
    assert sim.record.vmax_refined is not None
    law = ViscoelasticHertz(damping_time=1e-7)
    damped = TimeStep.choose(*args, rtol=1e-3, horizon=2e-4, law=law)
    assert damped.maxima == "sampled" and damped.integrator == "verlet"
    sim = Simulation(init.chain, init.u, init.v, dt=damped, law=law,
                     record=Recording(maxima=True))
    assert sim.record.vmax_refined is None  # at the step ends
    off = TimeStep.choose(*args, rtol=1e-3, horizon=2e-4,
                          recording=Recording(maxima=True, refined_maxima=False))
    assert off.maxima == "sampled"
    assert math.isfinite(off.error_estimate) and off.error_estimate <= 1e-3 * (1 + 1e-9)


def test_maxima_survive_save_and_load(tmp_path):
    from discrete import load, save

    init = _impact(60)
    for law, kind in ((None, "refined"), (ViscoelasticHertz(damping_time=1e-7), "sampled")):
        sim = Simulation(init.chain, init.u, init.v, rtol=1e-3, law=law)
        sim.run(5e-5, progress=False)
        save(tmp_path / f"{kind}.h5", sim)
        back = load(tmp_path / f"{kind}.h5")
        assert sim.time_step.maxima == back.time_step.maxima == kind
    plain = Simulation(init.chain, init.u, init.v)
    save(tmp_path / "plain.h5", plain)
    assert load(tmp_path / "plain.h5").time_step.maxima is None


def test_summary_names_the_maxima():
    from hertzchain.runner import run_simulation
    from hertzchain.scenario import parse_scenario

    def run(**chain):
        s = parse_scenario({"chain": {"sections": [{"n": 60}], **chain},
                            "initial": {"kind": "impact", "v0": 1.0},
                            "run": {"t_end": 1e-4, "rtol": 1e-3},
                            "record": {"running_max": True}})
        return run_simulation(s, save=False)[0]["rtol_maxima"]

    assert run() == "refined"
    assert run(law="viscoelastic_hertz", damping_time=1e-7) == "sampled"


@pytest.mark.parametrize("rtol", [1e-3, 1e-4])
def test_dissipative_chain_meets_rtol_with_sampled_maxima(rtol):
    """A viscoelastic impact on 150 grains (sampled maxima, velocity Verlet, s = 0.5):
    the running maxima of v over the peaks passed against the same run at a 16× smaller
    step (second order: its own error 1/256 of the run's) are within the estimate,
    hence within rtol, and within 50× of it."""
    init = _impact()
    law = ViscoelasticHertz(damping_time=2e-7)
    t_end = 6e-4
    step = TimeStep.choose(init.chain, init.u, init.v, rtol=rtol, horizon=t_end, law=law,
                           recording=Recording(maxima=True))
    assert step.maxima == "sampled" and step.integrator == "verlet"
    runs = []
    for dt in (step.dt, step.dt / 16):
        sim = Simulation(init.chain, init.u, init.v, dt=dt, law=law,
                         record=Recording(maxima=True))
        sim.run(t_end, progress=False)
        runs.append((np.array(sim.record.vmax), sim.v.copy()))
    (vm, _), (ref, vref) = runs
    scale = float(np.max(np.abs(ref)))
    done = (vref < 0.5 * ref) & (ref > 0.01 * scale)
    assert done.sum() >= 20
    true = float(np.max(np.abs(vm[done] - ref[done]))) / scale
    assert true <= step.error_estimate <= rtol * (1 + 1e-9), (true, step)
    assert true >= step.error_estimate / 50, (true, step)
