"""``hertzchain reproduce``: the command, caching, --force, bad items, and every item
module on a tiny configuration (figure functions drawing on a given ``ax``)."""

import json
import math
import os

import numpy as np
import pytest
from matplotlib.figure import Figure

from hertzchain._argtypes import jsonable
from hertzchain.cli import main
from hertzchain.paper import TABLE2, TABLE2_KEYS
from hertzchain.reproduce import ITEMS, check_items, reproduce
from hertzchain.reproduce.common import Context


def _ax():
    return Figure().subplots()


# -- the command on the cheapest item (δ0 = 0, a few hundred grains) ------------------
def test_cli_fig3_json_files_cache_and_force(tmp_path, capsys):
    out = tmp_path / "r"
    assert main(["reproduce", "fig3", "--json", "--out", str(out)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert set(data) == {"alpha_rho=0.2", "alpha_rho=5"}
    a, b = data["alpha_rho=0.2"], data["alpha_rho=5"]
    # paper Section 4: heavy-light fractures with no reflection, light-heavy reflects
    # compressive (negative velocities) waves and stays below u/ū_max = 1
    assert a["transmitted_class"] == "fracture" and a["n_transmitted_pulses"] >= 3
    assert a["max_abs_left_v_over_incident"] < 0.01
    assert b["reflected_class"] == "compressive" and b["min_left_v_over_incident"] < -0.1
    assert max(b["max_u_over_ubar"][g] for g in ("399", "400", "401", "402")) < 1.0
    assert a["free_flight_segments"]["399"] == 2          # "1st" and "2nd" free flight
    h5 = sorted((out / "runs").glob("fig3-*.h5"))  # discrete and continuum (Eq. 7) per case
    assert len(h5) == 4 and len([p for p in h5 if "continuum" in p.name]) == 2
    for name in ("figures/fig3.png", "report.md", "report.html"):
        assert (out / name).stat().st_size > 1000
    html = (out / "report.html").read_text()
    assert "data:image/png;base64," in html and "Where the paper does not hold" in html
    mtimes = [p.stat().st_mtime_ns for p in h5]
    # second run: every HDF5 file reused, none rewritten
    assert main(["reproduce", "fig3", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "0 simulations computed, 4 reused" in text
    assert [p.stat().st_mtime_ns for p in h5] == mtimes
    # --force recomputes (files rewritten, same numbers)
    assert main(["reproduce", "fig3", "--json", "--force", "--out", str(out)]) == 0
    again = json.loads(capsys.readouterr().out)
    assert [p.stat().st_mtime_ns for p in h5] != mtimes
    assert again["alpha_rho=0.2"]["n_transmitted_pulses"] == a["n_transmitted_pulses"]


def test_cli_bad_item_is_a_clear_error(tmp_path, capsys):
    assert main(["reproduce", "fig9", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "unknown item(s) 'fig9'" in err and "fig2" in err and "table2" in err
    assert not (tmp_path / "runs").exists()
    with pytest.raises(SystemExit):
        main(["reproduce", "--quick", "--full"])


def test_check_items_and_jsonable():
    assert check_items(None) == list(ITEMS)
    assert check_items(["table2", "fig2", "fig2"]) == ["fig2", "table2"]
    with pytest.raises(ValueError, match="fig1"):
        check_items(["fig1"])
    assert jsonable({"a": np.float64(1.5), "b": (math.nan, np.int64(2))}) == \
        {"a": 1.5, "b": [None, 2]}


def test_kernel_threads_quick_default_and_restore(tmp_path, monkeypatch):
    # --quick runs its tasks on one kernel thread (the serial kernel only, results
    # bitwise the same), --full in one process on numba's own count; restored after
    import numba

    import hertzchain.reproduce as R

    seen = []

    def fake_run(ctx, task, parts):
        seen.append((ctx.mode, numba.get_num_threads()))
        return None, [], {}

    monkeypatch.setattr(R, "_run", fake_run)
    before = numba.get_num_threads()
    for mode in ("quick", "full"):
        reproduce(["fig4"], mode=mode, out=tmp_path, progress=False, report=False)
    reproduce(["fig4"], mode="full", out=tmp_path, progress=False, report=False, threads=1)
    assert seen == [("quick", 1), ("full", before), ("full", 1)]
    assert numba.get_num_threads() == before
    with pytest.raises(ValueError, match="threads"), R.kernel_threads(0):
        pass
    assert numba.get_num_threads() == before


def test_api_counts_reuse(tmp_path):
    r1 = reproduce(["fig4"], out=tmp_path, progress=False, report=False)
    assert len(r1["computed"]) == 2 and not r1["reused"]
    r2 = reproduce(["fig4"], out=tmp_path, progress=False, report=False)
    assert not r2["computed"] and len(r2["reused"]) == 2
    assert r2["items"]["fig4"] == r1["items"]["fig4"]
    # paper Section 4 on Fig. 4: overshoot u/ū_max > 1 (alpha_kn = 0.2), below 1 (5)
    n = r1["items"]["fig4"]
    assert min(n["alpha_kn=0.2"]["max_u_over_ubar"][g] for g in (199, 200, 201, 202)) > 1
    assert max(n["alpha_kn=5"]["max_u_over_ubar"][g] for g in (199, 200, 201, 202)) < 1


# -- every item on a tiny configuration ---------------------------------------------
@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    from hertzchain.reproduce import fig2, fig5, fig6, fig7, fig8, table2

    ctx = Context(tmp_path_factory.mktemp("tiny"), progress=False)
    return ctx, {
        "fig2": fig2.run(ctx, n_grains={0.0: 150, 1e-3: 1500}, variants=("printed_nu025",)),
        "fig5": fig5.run(ctx, cases=("a", "b"), n_grains=1200, interface=900,
                         snapshot=1150, lead=100),
        "fig6": fig6.run(ctx, alphas=(0.5, 1.0, 2.0), length=150, every=10,
                         windows=(10, 50, 130)),
        "fig7": fig7.run(ctx, grid=2),
        "table2": table2.run(ctx, continuum=False),
        "fig8": fig8.run(ctx, points=("M", "P")),
    }


def test_tiny_figure_functions_draw_on_ax(tiny):
    from hertzchain.reproduce import fig2, fig5, fig6, fig7, fig8

    _, res = tiny
    ax = _ax()
    fig2.plot_panel(ax, res["fig2"], 0.0)
    assert ax.get_xlabel() and ax.get_ylabel() and ax.lines
    ax = _ax()
    fig5.plot_case(ax, res["fig5"][0])
    assert ax.get_ylabel() == r"$v_i/v_0$" and ax.lines
    ax = _ax()
    fig6.plot_speeds(ax, res["fig6"])
    assert ax.get_xscale() == "log" and len(ax.lines) == 6
    ax = _ax()
    fig6.plot_convergence(ax, res["fig6"])
    assert ax.lines
    ax = _ax()
    fig7.plot_phase_diagram(ax, res["fig7"])
    assert ax.get_xscale() == ax.get_yscale() == "log"
    ax = _ax()
    im = fig8.plot_map(ax, res["fig8"]["M"], "p")
    assert im.get_array().shape[1] == fig8.GRAINS_SHOWN


def test_tiny_numbers(tiny):
    _, res = tiny
    assert res["fig2"].vmax_over_v0[0.0] == pytest.approx(0.6816, abs=2e-4)
    # k_n printed in the paper (2x Hertz, nu = 0.25) halves the amplitude (docs/physics.md §1)
    assert res["fig2"].variants["printed_nu025"].mean < 0.6 * res["fig2"].vmax_over_v0[1e-3]
    a, b = res["fig5"]
    assert (a.numbers["transmitted"], a.numbers["reflected"]) == ("fracture", "expansive")
    assert (b.numbers["transmitted"], b.numbers["reflected"]) == ("squeeze", "compressive")
    mono = [r for r in res["fig6"]["alpha_rho"] if r.alpha_rho == 1.0][0]
    assert mono.far[2] == pytest.approx(mono.far[4], rel=1e-4)   # Eq. 5 for a settled wave
    for r in res["table2"]:
        for k in TABLE2_KEYS:
            assert r.discrete[k] == pytest.approx(TABLE2[r.point][k], abs=5e-4), (r.point, k)
        assert r.continuum is None and "disabled" in r.continuum_note
    named = {lab: (t, rr) for lab, t, rr in zip(res["fig7"].labels, res["fig7"].transmitted,
                                                 res["fig7"].reflected, strict=True) if lab}
    assert named["a"] == ("fracture", "expansive") and named["b"] == ("squeeze", "compressive")
    assert named["c"] == ("squeeze", "expansive") and named["d"] == ("fracture", "compressive")
    assert named["P"][1] == named["Q"][1] == "none"


def test_tiny_report(tiny):
    from hertzchain.reproduce import ItemRun, fig2, fig5, fig6, fig7, fig8, table2
    from hertzchain.reproduce.report import write_report

    ctx, res = tiny
    mods = {"fig2": fig2, "fig5": fig5, "fig6": fig6, "fig7": fig7, "fig8": fig8,
            "table2": table2}
    runs = []
    for name, mod in mods.items():
        figs = mod.figures(ctx, res[name]) if hasattr(mod, "figures") else []
        runs.append(ItemRun(name, res[name], figs, mod.to_json(res[name])))
    md, html = write_report(ctx, runs, 1.0)
    text = md.read_text()
    for heading in ("## Summary", "## Fig. 2", "## Fig. 5", "## Fig. 6", "## Fig. 7",
                    "## Fig. 8", "## Table 2", "## Where the paper does not hold"):
        assert heading in text, heading
    assert "not yet" in text                       # continuum column without continuum
    assert "printed formula, ν = 0.25" in text     # k_n convention with our number
    assert "compressive" in text and "expansive waves" in text
    for f in ("fig2", "fig5", "fig6", "fig7", "fig8"):
        assert (ctx.figures / f"{f}.png").exists()
    assert oct(os.stat(html).st_mode & 0o044) != "0o0"   # readable, not 0600
    json.dumps(jsonable({r.name: r.numbers for r in runs}), allow_nan=False)


def test_fig2_full_rtol_reads_refined_maxima(tmp_path):
    # --full (fig2.FULL["rtol"]): the precompressed impact at a stated accuracy, v̄max/v0
    # from the refined maxima.  Reference: the same impact at rtol = 1e-7 (Blanes-Moan 4,
    # refined maxima).  The rtol run's mean is within 2e-6 of it (measured 1.6e-7 on
    # 20,000 grains: each maximum within ~rtol = 1e-5 by construction, the errors of a
    # settled wave's maxima alike, so the mean's no larger); the default dt's sampled
    # maxima (--quick) are 1.1e-4 high (Verlet's O(dt²), discrete.timestep), so the test
    # fails if the rtol run read the samples or ran at the default dt.
    from hertzchain.reproduce import fig2
    from hertzchain.runner import run_simulation

    n = {1e-3: 1500}
    full = fig2.run(Context(tmp_path / "full", mode="full", progress=False), n_grains=n,
                    variants=())
    quick = fig2.run(Context(tmp_path / "quick", progress=False), n_grains=n, variants=())
    sc = fig2.scenario(1e-3, 1500).with_values({"run.rtol": 1e-7,
                                                "run.integrator": "blanes_moan4"})
    ref = fig2._plateau(run_simulation(sc)[1].record.vmax_refined).mean
    assert full.vmax_over_v0[1e-3] == pytest.approx(ref, rel=2e-6)
    assert 3e-5 < quick.vmax_over_v0[1e-3] / ref - 1 < 3e-4
    assert fig2.scenario(0.0, 150, rtol=1e-5).run.rtol is None   # gaps: the default dt


def test_fig2_full_gap_run_and_missing_refined_maxima(tmp_path, monkeypatch):
    # --full's rtol applies to the precompressed runs only: the δ0 = 0 impact (gaps: the
    # default dt and its sampled maxima) runs (a check on the rtol *argument* instead of the
    # scenario's raised there); an rtol run whose record lacks the refined maxima (a file
    # of an older version) raises instead of reading the O(dt²) samples
    from hertzchain.reproduce import fig2

    ctx = Context(tmp_path / "full", mode="full", progress=False)
    res = fig2.run(ctx, n_grains={0.0: 400}, variants=())
    assert res.vmax_over_v0[0.0] == pytest.approx(0.6816, abs=2e-3)
    real = fig2.run_models

    def stripped(*args, **kwargs):
        r = real(*args, **kwargs)
        r.simulation.record.vmax_refined = None
        return r

    monkeypatch.setattr(fig2, "run_models", stripped)
    with pytest.raises(ValueError, match="rtol = 1e-05 run has no refined maxima"):
        fig2.run(ctx, n_grains={1e-3: 300}, variants=())


# -- the acceptance numbers ---------------------------------------------------
def test_reproduce_fig2_table2_quick_json(tmp_path, capsys):
    assert main(["reproduce", "fig2", "table2", "--quick", "--json", "--out",
                 str(tmp_path)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert set(data) == {"fig2", "table2"}
    v = data["fig2"]["vmax_over_v0"]
    assert set(v) == {"0", "0.001"}
    assert v["0"] == pytest.approx(0.6816, abs=2e-4)
    assert v["0.001"] == pytest.approx(0.0822, abs=2e-4)
    assert set(data["table2"]) == {"M", "N", "P", "Q"}
    for point, row in data["table2"].items():
        assert set(row) == set(TABLE2_KEYS)
        for k in TABLE2_KEYS:
            assert row[k] == pytest.approx(TABLE2[point][k], abs=5e-4), (point, k)


def test_fig6_full_step(tmp_path):
    # --full runs Fig. 6 at fig6.FULL["dt_fraction"] (twice the default step): a settled
    # wave's front speed still meets Eq. 5 within 1e-4 (the tiny fixture's bound at the
    # default step; measured -2.6e-5 on --full's 4,000 grains, -2.0e-5 at the default)
    from hertzchain.reproduce import fig6

    assert fig6.scenario(1.0, 1.0, fig6.FULL).run.dt_fraction == fig6.FULL["dt_fraction"]
    assert fig6.scenario(1.0, 1.0).run.dt_fraction is None          # --quick: the default
    res = fig6.run(Context(tmp_path, mode="full", progress=False), alphas=(1.0,),
                   length=400, every=10, windows=(10, 50, 380))
    mono = res["alpha_rho"][0]
    assert mono.far[2] == pytest.approx(mono.far[4], rel=1e-4)


def test_fig7_full_step_keeps_labels(tmp_path):
    # --full runs the points with fig7.FULL["run"] (Blanes-Moan 4, 24x the default dt)
    # and FULL["record"] (an energy-grid row every 16 steps, not the automatic 1-2): the
    # labels are those of the default dt and grid (all 408 --full points:
    # benchmarks/full_dt.py for the dt, benchmarks/full_items.py --before for the grid)
    from hertzchain.reproduce import fig7

    quick = fig7.run(Context(tmp_path / "q", progress=False), grid=2)
    full = fig7.run(Context(tmp_path / "f", mode="full", progress=False), grid=2)
    assert full.extra["backend"] == "loop"
    assert full.transmitted == quick.transmitted and full.reflected == quick.reflected
    sc = fig7.scenario(2.0, 0.5, fig7.FULL["run"])
    assert sc["run"] == {**fig7.BASE["run"], **fig7.FULL["run"]}
    assert fig7.scenario(2.0, 0.5)["run"] == fig7.BASE["run"]
    assert fig7.scenario(2.0, 0.5, record=fig7.FULL["record"])["record"] == {
        "energy_every": 16} and "record" not in fig7.scenario(2.0, 0.5)


@pytest.mark.slow
def test_fig7_sweep_backend_matches_loop(tmp_path):
    # the Dask path (backend="sweep"): the same points through hertzchain.sweep give the
    # loop's labels
    from hertzchain.reproduce import fig7

    ctx = Context(tmp_path, progress=False)
    loop = fig7.run(ctx, grid=2, backend="loop")
    sweep = fig7.run(ctx, grid=2, backend="sweep", workers=1)
    assert sweep.transmitted == loop.transmitted and sweep.reflected == loop.reflected
    assert "points run on Dask" in ctx.notes["fig7"]
    again = fig7.run(ctx, grid=2, backend="sweep", workers=1)   # resumed: nothing to run
    assert again.transmitted == loop.transmitted
    assert " 0 points run on Dask" in ctx.notes["fig7"]
