"""The model-validity map: its sweep, its theory adapter, its axes, a small map, its figure.

The shipped map (``hertzchain/sweeps/model_validity.toml``: 5 x 5 interface ratios x 7
amplitudes x 3 exponents x 4 drag levels, 2,100 points) is far too long for a test; here

* the sweep file is checked against the rule that sizes it (:func:`law_rows`);
* the theory adapter against :func:`theory.strong_interface.predict_strong` and the
  exact discrete wave, computed independently;
* the "does not apply" reasons against the rules they come from (hertzchain's scenario
  validation for the continuum, predict_strong's domain for the theory);
* a small map (one interface, four cases in the sonic vacuum and under precompression,
  Hertz and n = 2, with and without drag) runs end to end through the sweep engine with
  the map's point function, and reproduce's ``--quick`` item on two of its points;
* the figure functions draw on a given ``ax``.

Expected (measured when the test was written, interface (2, 1/2)): under precompression
at the paper's amplitude (strain/δ0 = 0.09) Eq. 4 within 0.05 % and lattice acoustics
within 0.75 %; in the sonic vacuum Eq. 7 3.5 % and the quasi-particle theory 1.9 % (the
linear theory of Eqs. 9-13 was 8.9 % there); n = 2 in the sonic vacuum, the
quasi-particle theory 0.65 %.
"""

import dataclasses
import json
import math
from importlib.resources import files

import numpy as np
import pytest
from matplotlib.figure import Figure

from hertzchain.compare import THRESHOLDS
from hertzchain.reproduce import validity as V
from hertzchain.scenario import ScenarioError, parse_scenario
from hertzchain.sweep.engine import run_sweep
from hertzchain.sweep.spec import load_sweep_spec
from hertzchain.sweep.store import read_results
from hertzchain.sweep_plot import (
    plot_validity_amplitude,
    plot_validity_laws,
    save_sweep_figures,
    validity_summary,
)

SPEC = files("hertzchain") / "sweeps" / "model_validity.toml"
POINT_FUNCTION = "hertzchain.reproduce.validity:validity_point"


def _spec(alpha_rho, alpha_kn, cases):
    """The shipped sweep cut to these interfaces and (exponent, strain/δ0, damping) cases."""
    spec = load_sweep_spec(SPEC, validate_points=False)
    all_cases = V._cases()
    keep = [all_cases.index(c) for c in cases]
    new = {"alpha_rho_R": alpha_rho, "alpha_kn_R": alpha_kn}
    axes = tuple(dataclasses.replace(a, values=new[a.name]) if a.name in new else
                 dataclasses.replace(a, values=tuple(a.values[j] for j in keep))
                 for a in spec.axes)
    return dataclasses.replace(spec, axes=axes, _points=[])


def _continuum_reason(case) -> str:
    """Why hertzchain's rule refuses the continuum at the (2, 1/2) point of ``case``."""
    (p,) = _spec((2.0,), (0.5,), [case]).points()
    data = p.scenario.to_input()
    data["models"].update(continuum="auto", theory=False)
    try:
        parse_scenario(data)
    except ScenarioError as exc:
        return str(exc)
    return ""


# -- the sweep file and its sizing rule -----------------------------------------------------
def test_shipped_spec_is_the_documented_map():
    spec = load_sweep_spec(SPEC)
    assert spec.shape == (5, 5, 84) and spec.n_points == 2100
    # the continuum and the closed-form TheoryModel are off in the base: the point
    # function switches on, per point, what applies
    assert spec.base["models"]["continuum"] is False and spec.base["models"]["theory"] is False
    assert spec.base["initial"]["kind"] == "exact_wave"
    assert THRESHOLDS == (0.01, 0.10)
    assert POINT_FUNCTION in SPEC.read_text()  # the header says how to run it
    amp = [a for a, _ in V.AMPLITUDES]
    assert amp[0] == 1e-3 and amp[-2] == 100 and math.isinf(amp[-1])
    assert V.EXPONENTS == (1.5, 2.0, 2.5) and V.DAMPINGS[0] == 0 and V.DAMPINGS[-1] == 1
    cases = V._cases()
    assert len(cases) == len(set(cases)) == 84
    assert {c[0] for c in cases} == set(V.EXPONENTS)
    assert {c[2] for c in cases} == set(V.DAMPINGS)


def test_case_axes_are_the_sizing_rule():
    # every linked axis of the case dimension is law_rows()'s number, so the TOML cannot
    # drift from the rule that makes its measurement windows hold
    spec = load_sweep_spec(SPEC, validate_points=False)
    rows = V.law_rows()
    linked = {a.name: a for a in spec.axes if a.name == "delta0" or a.follows == "delta0"}
    assert set(linked) == {"delta0", "exponent", "drag", "strain_max", "n_left", "n_right",
                           "center", "t_end"}
    col = {"delta0": "delta0_over_d"}
    for name, axis in linked.items():
        assert list(axis.values) == [r[col.get(name, name)] for r in rows], name
    for r in rows:
        assert r["strain_max"] <= 1e-3  # Hertz's small-strain range
        if r["delta0_over_d"] > 0:
            assert r["strain_max"] / r["delta0_over_d"] == pytest.approx(r["strain_over_delta0"])
        # the drag level β·t_end, to the three digits of β
        assert r["drag"] * r["t_end"] == pytest.approx(r["damping"], rel=5e-3, abs=0)
        # KdV width (Hertz): the crossing extent (W/2) ln(1/SEPARATION), W = √(2δ0/ξ_m)
        if r["exponent"] == 1.5 and 0 < r["strain_over_delta0"] <= 0.09:
            w = math.sqrt(2 / r["strain_over_delta0"])
            assert r["crossing"] == pytest.approx(w / 2 * math.log(1e4), rel=0.02)
    hertz = [r for r in rows if r["exponent"] == 1.5 and r["damping"] == 0]
    # the widest wave (Hertz, strain/δ0 = 1e-3) needs the longest chain: ~2,900 | 2,500
    assert hertz[0]["n_left"] == 2872 and hertz[0]["n_right"] == 2492
    # a stiffer law's weak wave is narrower at the same strain/δ0: q² ≈ n ξ/δ0 ... shorter
    by = {(r["exponent"], r["strain_over_delta0"]): r for r in rows if r["damping"] == 0}
    assert by[(2.5, 1e-3)]["n_left"] < by[(2.0, 1e-3)]["n_left"] < by[(1.5, 1e-3)]["n_left"]


def test_linked_axes_toml_is_the_file():
    text = SPEC.read_text()
    assert V.linked_axes_toml() in text


# -- the theory adapter ---------------------------------------------------------------------
@pytest.fixture(scope="module")
def runs():
    """Discrete runs (sampled, no other model) of three cases at (α_ρ, α_kn) = (2, 1/2)."""
    from hertzchain.models import run

    spec = _spec((2.0,), (0.5,), [(1.5, math.inf, 0.0), (1.5, 0.09, 0.0), (2.0, 9.0, 0.0)])
    return [run(p.scenario, samples=True) for p in spec.points()]


def test_theory_adapter_equals_predict_strong(runs):
    import theory
    from theory.strong_interface import predict_strong

    mat, d = theory.PAPER_MATERIAL, theory.PAPER_DIAMETER
    k, m = theory.hertz_constant(d, mat), theory.grain_mass(d, mat.density)
    for result, eps, d0, name in ((runs[0], math.inf, 0.0, "quasi-particle"),
                                  (runs[1], 0.09, 1e-3 * d, "lattice acoustics")):
        got = V.theory_prediction(result)
        want = predict_strong(2.0, 0.5, eps)  # the interface, amplitude and law by hand
        # the exact incident wave's speed, solved again here (the adapter reads the run's)
        strain = V.SONIC_STRAIN if d0 == 0 else eps * d0 / d
        speed = theory.discrete_solitary_wave(k, m, d, d0, amplitude=strain * d).speed
        assert got.model == want.theory == name
        assert got.energy_transmission == pytest.approx(want.energy_transmission, rel=1e-9)
        assert got.energy_reflection == pytest.approx(want.energy_reflection, rel=1e-9)
        # the wave's speed to the solver's tolerance (its residual 1e-13, sampled grid)
        assert got.speed_transmitted == pytest.approx(want.speed_ratio * speed, rel=1e-9)


def test_theory_errors_use_the_comparison_windows(runs):
    from hertzchain.compare import analyse

    cmp = analyse(runs[0])
    errs = V.theory_errors(cmp)
    pred = V.theory_prediction(runs[0])
    disc = cmp.series["discrete"]
    got = disc.ratios_at(cmp.i_compare)
    assert not any(cmp.windows().values())  # every window holds in the sonic vacuum
    assert errs["energy"] == max(abs(pred.energy_transmission - got["Et_tr"]),
                                 abs(pred.energy_reflection - got["Et_re"]))
    assert errs["speed"] == abs(pred.speed_transmitted / disc.speeds["transmitted"] - 1)
    assert errs["error"] == max(errs["energy"], errs["speed"]) and errs["note"] == ""
    # measured when written: 1.9 % (the linear theory of Eqs. 9-13: 8.9 %)
    assert errs["error"] < 0.03
    # a comparison before the crossing: no energy, and the note says why (compare's words)
    early = dataclasses.replace(cmp, i_compare=max(cmp.i_cross - 1, 0))
    e2 = V.theory_errors(early)
    assert math.isnan(e2["error"]) and math.isnan(e2["energy"])
    assert e2["note"].startswith(early.windows()["energy"]) and e2["note"]


def test_does_not_apply_carries_the_rules_reason(runs):
    from theory.strong_interface import predict_strong

    # the theory: predict_strong's own refusal of n != 3/2 under precompression
    with pytest.raises(V.DoesNotApply) as info:
        V.theory_prediction(runs[2])
    with pytest.raises(ValueError) as direct:
        predict_strong(2.0, 0.5, 9.0, exponent=2.0)
    assert str(info.value) == str(direct.value)
    # the continuum: hertzchain's scenario rule, asked independently here
    for case in [(2.0, 9.0, 0.0), (1.5, math.inf, 0.1), (1.5, 0.09, 0.0)]:
        (p,) = _spec((2.0,), (0.5,), [case]).points()
        sc, reason = V.with_models(p.scenario)
        assert reason == _continuum_reason(case)
        # "auto"'s one rule picks the quasi-continuum from strain/δ0 = 9 and at δ0 = 0
        # without drag: the point names it, else keeps "auto"; every model steps at its
        # own method and dt_safety (the quasi-continuum's position Verlet at 0.8)
        strong = case[1] >= 9.0 and case[2] == 0.0
        assert sc.models.continuum == (False if reason else "qc" if strong else "auto")
        assert (sc.models.integrator, sc.models.order, sc.models.dt_safety) == (None,) * 3
        if sc.models.continuum == "qc":
            assert sc.models.continuum_step("qc") == ("position_verlet", 0.8)
        assert not sc.models.theory
    assert V.with_models(p.scenario)[1] == ""  # the lossless Hertz chain: it runs


def test_energy_partition_uses_the_chains_law():
    # compare's potential energy for F = k δ^n is k/(n+1)(δ^{n+1} − δ0^{n+1}), not Hertz's
    import discrete
    from hertzchain.measure import grain_energies

    class Chain:
        mass = np.array([2.0, 3.0])
        k = np.array([5.0, 7.0, 11.0])
        delta0 = np.array([0.1, 0.2, 0.3])

    strain = np.array([0.05, -0.3, 0.02])
    kin, pot = grain_energies(Chain, np.array([1.0, 2.0]), strain, discrete.PowerLaw(2.0))
    r = Chain.delta0 + strain
    want = Chain.k / 3 * (np.maximum(r, 0) ** 3 - Chain.delta0 ** 3)
    assert np.allclose(pot, want, rtol=1e-13, atol=0) and np.allclose(kin, [1.0, 6.0])
    # Hertz by default: (2/5) k (δ^{5/2} − δ0^{5/2})
    _, hertz = grain_energies(Chain, np.zeros(2), strain)
    assert np.allclose(hertz, 0.4 * Chain.k * (np.maximum(r, 0) ** 2.5 - Chain.delta0 ** 2.5),
                       rtol=1e-12, atol=0)


# -- a small map, end to end -----------------------------------------------------------------
SMALL = [(1.5, math.inf, 0.0), (2.0, math.inf, 0.0), (2.0, 9.0, 0.0), (1.5, math.inf, 0.1)]


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    spec = _spec((2.0,), (0.5,), SMALL)
    out = tmp_path_factory.mktemp("validity")
    outcome = run_sweep(spec, out=out, point_function=POINT_FUNCTION, workers=1,
                        processes=False, progress=False, warmup=None)
    return outcome, read_results(outcome.table)


def test_small_map_records_every_model_that_applies(small):
    outcome, res = small
    assert outcome.n_failed == 0 and len(res) == len(SMALL)
    assert set(res["point_function"]) == {POINT_FUNCTION}
    by = {(float(n), float(f"{a:.2g}"), round(float(g), 2)): j for j, (n, a, g) in enumerate(
        zip(res["exponent"], res["incident_strain_over_delta0"], res["damping"],
            strict=True))}  # the measured amplitude, to two digits (as the summary's groups)
    assert sorted(by) == sorted((n, a, g) for n, a, g in SMALL)
    hertz, n2, n2_pre, drag = (by[c] for c in SMALL)
    cont, th = res["continuum_error"], res["theory_error"]
    capp = np.asarray(res["continuum_applies"]).astype(bool)
    tapp = np.asarray(res["theory_applies"]).astype(bool)
    # the lossless Hertz chain: both models, the quasi-continuum (launched band-limited:
    # measured 0.15 %; 2.0 % from a cubic-spline launch) and the quasi-particle theory
    assert capp[hertz] and tapp[hertz] and res["continuum_model"][hertz] == "qc"
    assert cont[hertz] <= THRESHOLDS[0] and th[hertz] < 0.03
    # n = 2 in the sonic vacuum: the theory applies (measured 0.65 %)
    assert tapp[n2] and res["theory_model"][n2] == "quasi-particle" and th[n2] < THRESHOLDS[0]
    # the continuum runs exactly where hertzchain's rule admits it; elsewhere the point
    # is kept with the rule's reason
    for case in SMALL:
        j, why = by[case], _continuum_reason(case)
        assert capp[j] == (not why)
        if why:
            assert math.isnan(cont[j]) and res["continuum_note"][j] == f"does not apply: {why}"
        else:
            assert res["continuum_model"][j] in ("eq4", "eq7", "qc")
    # n = 2 under precompression: the theory does not apply; the point is kept, with why
    assert not tapp[n2_pre] and math.isnan(th[n2_pre])
    assert res["theory_note"][n2_pre].startswith("does not apply: exponent = 2 needs")
    assert res["status"][n2_pre] == "ok" and math.isfinite(res["Et_tr"][n2_pre])
    # a damped chain: the lossless theory is compared (its error grows with the drag)
    assert tapp[drag] and math.isfinite(th[drag]) and th[drag] > th[hertz]


def test_small_map_summary_and_figure(small, tmp_path):
    _, res = small
    rows = validity_summary(res)
    key = {(r["model"], r["exponent"], r["damping"], r["strain_over_delta0"]): r for r in rows}
    na = key[("theory", 2.0, 0.0, 9.0)]
    assert na["n"] == 1 and na["does_not_apply"] == 1 and na["not_compared"] == 0
    assert "needs strain_over_delta0 = inf" in na["does_not_apply_reasons"]
    cna = key[("continuum", 1.5, 0.1, math.inf)]
    why = _continuum_reason((1.5, math.inf, 0.1))
    assert cna["does_not_apply"] == (1 if why else 0)
    if "[chain] drag = " in why:  # one reason for every drag level: the value elided
        assert "[chain] drag = …" in cna["does_not_apply_reasons"]
    ok = key[("theory", 1.5, 0.0, math.inf)]
    assert ok["within_10"] == 1 and ok["theories"] == "quasi-particle"
    assert ok["median_error"] == ok["max_error"] == pytest.approx(float(
        res["theory_error"][np.flatnonzero((res["exponent"] == 1.5) & (res["damping"] == 0))[0]]))
    written = save_sweep_figures(res, tmp_path / "map.png")
    validity = [p for p in written if p.name == "validity_map.png"]
    assert validity and validity[0].stat().st_size > 10_000


# -- reproduce's item -------------------------------------------------------------------------
def test_reproduce_item_quick(tmp_path, monkeypatch):
    # the report's coarse map (``--quick``), cut to two of its points here
    from hertzchain.report import Report
    from hertzchain.reproduce import ITEMS
    from hertzchain.reproduce.common import Context

    assert "validity" in ITEMS
    monkeypatch.setattr(V, "QUICK", (V.Block((2.0,), (0.5,), (0.09, math.inf)),))
    ctx = Context(tmp_path, progress=False)
    table = V.run(ctx)
    assert len(table) == 2
    data = V.to_json(table)
    pre, sv = data["points"]
    assert pre["delta0_over_d"] == pytest.approx(1e-3) and sv["delta0_over_d"] == 0.0
    # (the sonic vacuum's quasi-continuum, launched band-limited: measured 0.15 %)
    assert pre["continuum_error"] <= THRESHOLDS[0] and sv["continuum_error"] <= THRESHOLDS[0]
    assert (pre["theory_model"], sv["theory_model"]) == ("lattice acoustics", "quasi-particle")
    assert pre["theory_error"] <= THRESHOLDS[0] and sv["theory_error"] <= THRESHOLDS[1]
    assert sv["incident_strain_over_delta0"] is None  # inf in JSON: the sonic vacuum
    assert pre["continuum_applies"] is True and sv["theory_applies"] is True
    figs = V.figures(ctx, table)
    assert figs[0][0].exists()
    rep = Report("t")
    V.report(rep, table, figs)
    text = rep.to_markdown(tmp_path)
    assert "within 10 %" in text and "sonic vacuum" in text and "median" in text
    assert "continuum (Eq. 4)" in text and "continuum (qc)" in text
    assert "theory (lattice acoustics)" in text and "theory (quasi-particle)" in text
    # one small file per point (scenario and row; the runs are compared in memory,
    # not written), and a second run reuses them: the same table, bit for bit
    assert sorted(p.name.split("-")[:2] == ["validity", "point"] for p in ctx.computed) \
        == [True, True] and sorted(ctx.runs.iterdir()) == sorted(ctx.computed)
    ctx2 = Context(tmp_path, progress=False)
    again = V.run(ctx2)
    assert not ctx2.computed and sorted(ctx2.reused) == sorted(ctx.computed)
    assert json.dumps(V.to_json(again)) == json.dumps(data)


@pytest.mark.parametrize("mode", ["quick", "full"])
def test_reproduce_maps_are_points_of_the_shipped_sweep(mode, tmp_path):
    # --quick and --full run a subset of the shipped map's points: every axis value is
    # one of the sweep's (the sweep's logspace ratios to round-off: 2.0 vs 10**(log10(4)/2))
    from hertzchain.reproduce.common import Context

    blocks = V.FULL if mode == "full" else V.QUICK
    ctx = Context(tmp_path, mode=mode, progress=False)
    points = V._points(ctx)
    assert len(points) == sum(len(b.alpha_rho) * len(b.alpha_kn) * len(b.amplitudes)
                              * len(b.exponents) * len(b.dampings) for b in blocks)
    shipped = load_sweep_spec(SPEC).points()
    for p in points:
        same = [q for q in shipped if q.values.keys() == p.values.keys()
                and all(np.isclose(q.values[k], v, rtol=1e-12, atol=0)
                        for k, v in p.values.items())]
        assert len(same) == 1, p.label()
    if mode == "quick":  # the lossless Hertz chain only: --quick stays a few minutes
        assert {p.scenario.chain.exponent for p in points} == {1.5}
        assert {p.scenario.chain.drag for p in points} == {0.0} and len(points) == 3
    else:
        assert {p.scenario.chain.exponent for p in points} == set(V.EXPONENTS)
        levels = {round(p.scenario.chain.drag * p.scenario.run.t_end, 2) for p in points}
        assert levels == set(V.DAMPINGS)


# -- the figure functions ---------------------------------------------------------------------
def _table():
    """A small synthetic table (numbers for drawing, not physics): two laws, two models."""
    rows = []
    for n, g in ((1.5, 0.0), (1.5, 0.1), (2.0, 0.0)):
        for amp in (0.01, 9.0, math.inf):
            for a in (0.5, 2.0):
                capp = (n, g) == (1.5, 0.0)
                tapp = n == 1.5 or math.isinf(amp)
                rows.append({"alpha_rho": a, "alpha_kn": 1 / a, "exponent": n, "damping": g,
                             "incident_strain_over_delta0": amp,
                             "continuum_error": 0.003 * a if capp else math.nan,
                             "theory_error": 0.02 / a if tapp else math.nan,
                             "continuum_applies": capp, "theory_applies": tapp,
                             "continuum_model": ("eq4" if amp < 0.5 else "eq7") if capp else "",
                             "theory_model": "quasi-particle" if tapp and amp > 2.6 else
                             ("lattice acoustics" if tapp else ""),
                             "continuum_note": "" if capp else "does not apply: x",
                             "theory_note": "" if tapp else "does not apply: y",
                             "continuum_stopped_by": "t_end"})
    t = V._Table({k: np.array([r[k] for r in rows]) for k in rows[0]})
    t.attrs = {"name": "synthetic", "n_ok": len(rows), "n_failed": 0}
    return t


def test_figure_functions_draw_on_a_given_ax():
    t = _table()
    fig = Figure()
    ax = fig.add_subplot(1, 2, 1)
    assert plot_validity_amplitude(ax, t, model="theory", legend=True)
    # one marker per interface and amplitude compared, the median, the sonic-vacuum tick
    markers = [ln for ln in ax.lines if ln.get_linestyle() == "None"
               and ln.get_marker() not in ("x", "None")]
    assert len(markers) == 6
    assert "sonic\nvacuum" in [lab.get_text() for lab in ax.get_xticklabels()]
    assert ax.get_yscale() == "log" and ax.get_legend() is not None
    # the law n = 2: the theory does not apply under precompression — "n/a" there
    bx = fig.add_subplot(1, 2, 2)
    assert plot_validity_laws(bx, t, model="theory", exponent=2.0)
    assert sum(txt.get_text() == "n/a" for txt in bx.texts) == 2
    assert plot_validity_laws(bx, t, model="continuum", exponent=1.5)
    labels = bx.get_legend().get_texts()
    assert any("(n/a)" in lab.get_text() for lab in labels)  # the drag level: no continuum
    # a law the table does not have: a note, nothing drawn
    cx = Figure().add_subplot()
    assert not plot_validity_amplitude(cx, t, exponent=2.5)


def test_a_point_whose_waves_stay_at_the_interface_is_run_longer():
    """Light → heavy onto a soft side, (α_ρ, α_kn) = (4, 1/4) in the sonic vacuum: with the
    row's run length the discrete run's waves have not left the interface (energies not
    compared); :func:`validity.longer_run` stretches the run by the incident over the
    predicted transmitted speed (~1/0.27) and lengthens the left section, after which the
    energies are compared and the quasi-continuum is within 5 % (measured 2.9 %).  A
    compared point, (2, 1/2), is left as it is (None)."""
    from hertzchain.compare import analyse
    from hertzchain.models import run

    [p] = _spec((4.0,), (0.25,), [(1.5, math.inf, 0.0)]).points()
    sc, _ = V.with_models(p.scenario)
    first = run(sc, samples=True)
    cmp = analyse(first)
    assert math.isnan(cmp.summary()["continuum_energy"])
    longer = V.longer_run(first, cmp)
    assert longer["run.t_end"] > 3.0 * float(sc.run.t_end)
    grains = longer["chain.sections.0.n"] - sc.chain.sections[0].n
    assert grains > 0 and longer["initial.center"] == sc.initial.center + grains
    row = V.validity_point(p.scenario)
    assert row["continuum_error"] <= THRESHOLDS[1] / 2
    [q] = _spec((2.0,), (0.5,), [(1.5, math.inf, 0.0)]).points()
    sc2, _ = V.with_models(q.scenario)
    done = run(sc2, samples=True)
    assert V.longer_run(done, analyse(done)) is None
