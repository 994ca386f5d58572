"""Ensemble sweeps: the [ensemble] table, batches on Dask, per-realisation records, statistics.

A realisation's record from a batch must equal the same realisation run alone (every
summary key but the wall time, ``==`` on the numbers); the ``/ensemble`` table must be
NumPy's statistics of the per-realisation column; a bad ``[ensemble]`` names its key.
"""

import math

import numpy as np
import pytest

from discrete.ensemble import ensemble_statistics
from hertzchain.sweep import SweepError, parse_sweep_spec, read_results, run_sweep
from hertzchain.sweep.engine import ensemble_batches
from hertzchain.sweep.ensemble import ENSEMBLE_POINT_FUNCTION, realisation
from hertzchain.sweep.store import records_from_table


def _spec(**ensemble):
    return parse_sweep_spec({
        "name": "ens",
        "base": {"chain": {"delta0_over_d": 1e-3,
                           "sections": [{"n": 30, "disorder_mass": 0.1}]},
                 "initial": {"kind": "impact", "v0": 0.1}, "run": {"t_end": 1.2e-4},
                 "models": {"theory": False}},
        "sweep": {"axes": [{"path": "chain.sections.0.disorder_mass", "name": "sigma",
                            "values": [0.05, 0.2]}]},
        "ensemble": {"seeds": 5, "batch": 3, **ensemble}})


def test_spec_adds_the_seed_axis():
    spec = _spec()
    assert spec.n_points == 10 and spec.axes[-1].name == "seed"
    assert spec.axes[-1].path == "chain.sections.0.seed"
    assert [p.values["seed"] for p in spec.points()[:5]] == [0, 1, 2, 3, 4]
    assert "seed" not in [a["name"] for a in spec.to_dict()["axes"]]
    batches = ensemble_batches(spec, spec.points())
    assert [len(b) for b in batches] == [3, 2, 3, 2]  # per value of sigma, 3 at most
    assert all(len({p.values["sigma"] for p in b}) == 1 for b in batches)


@pytest.mark.parametrize("bad, match", [
    ({"seeds": 0}, "seeds"), ({"batch": 1.5}, "batch"), ({"colour": 1}, "unknown"),
    ({"path": ""}, "path")])
def test_bad_ensemble_table(bad, match):
    with pytest.raises(SweepError, match=match):
        _spec(**bad)


def test_ensemble_sweep_equals_one_by_one(tmp_path):
    spec = _spec()
    out = run_sweep(spec, out=tmp_path / "s", workers=1, processes=False, progress=False)
    assert out.n_ok == 10 and out.n_failed == 0
    res = read_results(out.table)
    assert set(res["point_function"]) == {ENSEMBLE_POINT_FUNCTION}
    for i, p in enumerate(spec.points()):
        alone = realisation(p.scenario)
        row = res.row(i)
        for key, val in alone.items():
            if key in ("wall_time",):
                continue
            got = row[key] if key in row else row[f"summary.{key}"]
            if key == "amplitude_profile":
                assert np.array_equal(res[key][i], np.array(val)), key
            elif isinstance(val, float) and math.isnan(val):
                assert math.isnan(got), key
            elif val is None:
                assert got in ("", None, -1), key
            else:
                assert got == val, key
    # the profile column is 2-D and survives the table round trip
    assert res["amplitude_profile"].shape == (10, 30)
    back = records_from_table(out.table)
    assert back[res["id"][3]]["summary"]["amplitude_profile"] == res[
        "amplitude_profile"][3].tolist()
    # statistics: NumPy's, per value of sigma
    ens = res.ensemble
    assert ens["sigma"].tolist() == [0.05, 0.2] and ens["n_realisations"].tolist() == [5, 5]
    for g, sigma in enumerate((0.05, 0.2)):
        sel = res["sigma"] == sigma
        for key in ("decay_rate", "amplitude_last", "front_speed_tr"):
            st = ensemble_statistics(res[key][sel])
            for stat in ("mean", "sem", "q50", "q5_err"):
                assert ens[f"{key}_{stat}"][g] == pytest.approx(float(st[stat]), rel=1e-13,
                                                                nan_ok=True), (key, stat)
        prof = res["amplitude_profile"][sel]
        assert np.allclose(ens["profile_mean"][g], prof.mean(axis=0), rtol=1e-13)
        rate = ens["decay_rate_mean"][g]
        if rate > 0:
            assert ens["localisation_length"][g] == pytest.approx(1 / rate, rel=1e-13)
    assert np.array_equal(ens["profile_grains"], np.arange(30))
    # the plot: one curve (mean log amplitude) per value of sigma
    from matplotlib.figure import Figure

    from hertzchain.sweep_plot import plot_ensemble

    ax = Figure().add_subplot()
    assert plot_ensemble(ax, res) and len(ax.get_lines()) == 2
    # a rerun finds every realisation done
    again = run_sweep(spec, out=tmp_path / "s", workers=1, processes=False, progress=False)
    assert again.n_run == 0 and again.n_skipped == 10


def test_realisations_are_built_as_the_runner_builds_them():
    """A batch's chains (one geometry, many seeds: Chain.from_sections_seeds), initial
    states and steps are bit for bit build_simulation's, seed by seed; a batch mixing
    other axes (two disorder strengths, a second disordered section) too."""
    import dataclasses

    from hertzchain.runner import build_simulation
    from hertzchain.sweep.ensemble import _build

    scen = [p.scenario for p in _spec().points()]
    two = dataclasses.replace(scen[0].chain, sections=(
        scen[0].chain.sections[0], dataclasses.replace(scen[0].chain.sections[0], seed=7)))
    scen.append(scen[1].replace(chain=two))  # two disordered sections: built alone
    sims = _build(scen)
    for s, sim in zip(scen, sims, strict=True):
        _, _, ref = build_simulation(s, energy_grid=False)
        for name in ("mass", "k", "delta0", "diameter"):
            assert np.array_equal(getattr(sim.chain, name), getattr(ref.chain, name)), name
        assert np.array_equal(sim.u, ref.u) and np.array_equal(sim.v, ref.v)
        assert (sim.dt, sim.wall_left, sim.wall_right, sim.integrator) == (
            ref.dt, ref.wall_left, ref.wall_right, ref.integrator)
    assert not np.array_equal(sims[0].chain.mass, sims[1].chain.mass)  # the seeds differ


def test_arrival_times_and_front_speed():
    """``arrival_time_last`` is the kernel's time of the last grain's maximum, bit for
    bit; ``front_speed_tr`` is 1/slope of NumPy's polyfit of the reached grains' times
    of the fit range against their centres (to round-off: 1e-12, another arithmetic)."""
    from discrete.ensemble import run_ensemble
    from hertzchain.sweep.ensemble import _build, fit_range, front_speeds, realisations

    spec = parse_sweep_spec({
        "name": "ens", "base": {"chain": {"delta0_over_d": 1e-3,
                                          "sections": [{"n": 60, "disorder_mass": 0.1}]},
                                "initial": {"kind": "impact", "v0": 0.1},
                                "run": {"t_end": 3e-4}, "models": {"theory": False}},
        "sweep": {"axes": []}, "ensemble": {"seeds": 4}})
    scen = [p.scenario for p in spec.points()]
    recs = realisations(scen)
    sims = _build(scen)
    res = run_ensemble(sims, 3e-4, times=True)
    first, last = fit_range(60)
    for q, (rec, sim) in enumerate(zip(recs, sims, strict=True)):
        assert rec["arrival_time_last"] == res.vmax_time[q, -1] > 0
        x = (np.cumsum(sim.chain.diameter) - 0.5 * sim.chain.diameter)[first:last + 1]
        t = res.vmax_time[q, first:last + 1]
        ok = res.vmax[q, first:last + 1] > 0
        assert ok.sum() >= 5
        ref = 1.0 / np.polyfit(x[ok], t[ok], 1)[0]
        assert rec["front_speed_tr"] == pytest.approx(ref, rel=1e-12)
        # the pulse crosses the 60 grains in about t_end: a speed of that order
        assert 0.3 < rec["front_speed_tr"] * 3e-4 / (x[-1] - x[0]) < 3
    # fewer than 5 reached grains, or times that do not vary: NaN
    x = np.arange(8.0)[None].repeat(2, axis=0)
    t = np.array([2.0 * np.arange(8.0), np.ones(8)])
    reached = np.array([[True] * 4 + [False] * 4, [True] * 8])
    assert np.isnan(front_speeds(x, t, reached)).all()
    assert front_speeds(x[:1], t[:1], np.ones((1, 8), bool))[0] == pytest.approx(0.5, rel=1e-14)
