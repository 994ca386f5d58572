"""Property tests of :mod:`hertzchain.measure`: labels only inside their windows, and
``run`` and ``compare`` reading the same windows, on small random scenarios.

Hypothesis draws two-section chains of 20–90 grains per section (α_ρ, α_kn in
[0.3, 3]), an impact (optionally with a striker) or an exact wave at δ0 = 0, a wall or a
free right end and a stop time from before the interface to long after a wave reached
the far end, so that every window is met and missed.  A run takes ~0.1 s; each test
draws 15 scenarios (a few seconds).
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hertzchain.scenario import ScenarioError, parse_scenario


@st.composite
def scenarios(draw):
    n_left = draw(st.integers(20, 90))
    n_right = draw(st.integers(20, 90))
    ar = draw(st.sampled_from([0.3, 0.5, 1.0, 2.0, 3.0]))
    ak = draw(st.sampled_from([0.3, 1.0, 3.0]))
    if draw(st.booleans()):
        initial = {"kind": "impact", "v0": 1.0,
                   "striker_mass": draw(st.sampled_from([1.0, 1.0, 3.0]))}
    else:
        initial = {"kind": "exact_wave", "center": n_left // 3, "velocity_max": 0.5}
    # a run to 0.2 ... 3 times the time the incident wave needs to cross both sections
    t_end = draw(st.floats(0.2, 3.0)) * (n_left + n_right) * 5e-3 / 600.0
    return {"chain": {"right_wall": draw(st.sampled_from(["paper", "free"])),
                      "sections": [{"n": n_left},
                                   {"n": n_right, "alpha_rho": ar, "alpha_kn": ak}]},
            "initial": initial, "run": {"t_end": t_end, "max_steps": 200_000},
            "models": {"theory": True}}


def _scenario(data):
    try:
        return parse_scenario(data)
    except ScenarioError:  # (e.g. a wave that does not fit): nothing to check
        return None


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scenarios())
def test_labels_and_speeds_only_inside_their_windows(data):
    from hertzchain.runner import run_simulation

    sc = _scenario(data)
    if sc is None:
        return
    try:
        s, sim = run_simulation(sc, save=False)
    except ScenarioError:
        return
    labelled = s["transmitted"] is not None
    assert labelled == (s["reflected"] is not None) == (s["n_transmitted_pulses"]
                                                        is not None)
    # a label: the waves separated, and no wave had reached a chain end before the
    # final state it is read on
    if labelled:
        assert s["separated"] and s["end_reached"] == "" and not s["labels_note"]
        assert math.isinf(s["t_end_reached"])
    else:
        assert s["labels_note"]
    if s["end_reached"]:
        assert s["t_end_reached"] <= s["t"]
    # a number says nothing, a NaN says why
    for key in ("front_speed_tr", "front_speed_re"):
        assert math.isnan(s[key]) == bool(s[f"{key}_note"]), (key, s[key], s[f"{key}_note"])
    if math.isfinite(s["front_speed_re"]):
        assert s["reflected"] != "none"
    if any(math.isfinite(s[k]) for k in ("Et_tr", "Et_re", "Ek_tr")):
        assert s["separated"] and s["t_separated"] <= s["t"]
        assert s["t_incident"] < s["t_separated"]
        # a conservative chain: the totals balance (the waves are in the two sections;
        # a striker keeps some energy: then less than 1)
        total = s["Et_tr"] + s["Et_re"]
        assert s["Ed"] == 0.0 and total <= 1 + 1e-4
        if data["initial"].get("striker_mass", 1.0) == 1.0:
            assert abs(total - 1) <= 1e-4, total
    else:
        assert s["ratios_note"]
    # the end the summary names did receive energy on the grid, and only then
    if s["end_reached"]:
        t, ek, ep = sim.record.energy_grids()
        g = max(1, math.ceil(10 / sim.record.energy_coarsen))
        e = np.abs(ek + ep)
        cols = e[:, :g] if s["end_reached"] == "left" else e[:, -g:]
        after = t >= s["t_end_reached"]
        assert cols[after].sum(axis=1).max() > 1e-4 * e.sum(axis=1).max()


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scenarios())
def test_compare_reads_the_run_s_windows(data):
    from hertzchain.compare import analyse
    from hertzchain.models import run

    sc = _scenario(data)
    if sc is None:
        return
    try:
        result = run(sc, samples=True)
    except ScenarioError:
        return
    s = result.discrete.summary
    cmp = analyse(result)
    th = cmp.differences["theory"]
    # no continuum: every sample is comparable, and the comparison time is the run's end
    # (a sample's nominal time: the state is the first step at or after it)
    assert 0 <= s["t"] - cmp.t_compare < s["dt"]
    one = result.summary()["incident_strain"]
    assert one == s["incident_strain"] or (math.isnan(s["incident_strain"])
                                           and math.isnan(one))
    if not result.theory.interface_theory:
        # (a striker's train: the chain theory compares its leading peak, no Table 2)
        assert "Et_tr" not in th and not math.isfinite(cmp.errors.get("theory", {}).get(
            "energy", math.nan))
        return
    energy = [th[k][2] for k in ("Et_tr", "Et_re", "Ek_tr")]
    crossed = cmp.i_compare >= cmp.i_cross
    # the energy partition is compared exactly where the run measures one
    assert all(np.isfinite(energy)) == (crossed and s["separated"]), (energy, s["separated"])
    if not all(np.isfinite(energy)):
        assert not any(np.isfinite(energy))
        assert "Et_tr" in cmp.unmeasured["theory"]
        assert math.isnan(cmp.errors["theory"]["energy"])
        assert math.isnan(cmp.summary()["theory_d_Et_tr"])
    # a reflected front in compare only where the run measured one
    if math.isfinite(th["speed_reflected"][2]):
        assert math.isfinite(s["front_speed_re"])
    # an error only from measured parts
    if math.isfinite(cmp.errors["theory"]["error"]):
        assert math.isfinite(cmp.errors["theory"]["energy"])
        assert math.isfinite(cmp.errors["theory"]["speed"])
