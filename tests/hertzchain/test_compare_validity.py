"""The shipped model-validity sweep (issue 12), reduced: every model at each point.

The full map (``hertzchain/sweeps/model_validity.toml``, 5 x 5 interface ratios x 7
amplitudes, incident strain / δ0 = 1e-3 … 100 and the sonic vacuum) takes about an hour
on one loaded core; here two interfaces at two of its amplitudes run through the sweep
engine — with :func:`hertzchain.compare.compare_point` by default, as ``[base.models]``
asks for every model — and the table, the summary numbers and the figure are checked,
as are the amplitude rows against the rule that sizes them.

Expected (and measured when the test was written): under precompression at the paper's
amplitude (strain/δ0 = 0.09) the corrected Eq. 4 is within 1 % of the discrete chain
(energy differences ~3e-4 of the incident energy, speeds ~1e-4) and the linear theory
within 1 % too (~3e-3); in the sonic vacuum both are only within 10 % (Eq. 7: ~3e-2 of
the energy; the theory's linear-acoustic energies ~2e-2–6e-2).
"""

import dataclasses
import json
import math
from importlib.resources import files

import numpy as np
import pytest

from hertzchain.compare import THRESHOLDS
from hertzchain.reproduce.validity import AMPLITUDES, amplitude_row
from hertzchain.sweep.engine import (
    DEFAULT_POINT_FUNCTION,
    MODELS_POINT_FUNCTION,
    default_point_function,
    run_sweep,
)
from hertzchain.sweep.spec import Axis, load_sweep_spec
from hertzchain.sweep.store import read_results
from hertzchain.sweep_plot import save_sweep_figures, validity_summary

SPEC = files("hertzchain") / "sweeps" / "model_validity.toml"


def test_shipped_spec_is_the_documented_map():
    spec = load_sweep_spec(SPEC)
    assert spec.shape == (5, 5, 7) and spec.n_points == 175
    assert spec.base["models"]["continuum"] == "auto"
    assert spec.base["initial"]["kind"] == "exact_wave"
    assert THRESHOLDS == (0.01, 0.10)
    d0 = [a for a in spec.axes if a.name == "delta0"][0].values
    assert min(d0) == 0.0 and max(d0) == pytest.approx(1e-3)  # up to the sonic vacuum
    # strain/δ0 from 1e-3 (the "1e-3 δ0") to 100, then the sonic vacuum
    amp = [a for a, _ in AMPLITUDES]
    assert amp[0] == 1e-3 and amp[-2] == 100 and math.isinf(amp[-1])


def test_amplitude_rows_are_the_sizing_rule():
    # every linked axis of the amplitude dimension is validity.amplitude_row's number,
    # so the TOML cannot drift from the rule that makes its measurement windows hold
    spec = load_sweep_spec(SPEC)
    rows = [amplitude_row(*a) for a in AMPLITUDES]
    linked = {a.name: a for a in spec.axes if a.name == "delta0" or a.follows == "delta0"}
    assert set(linked) == {"delta0", "strain_max", "n_left", "n_right", "center", "t_end"}
    for name, axis in linked.items():
        key = "delta0_over_d" if name == "delta0" else name
        assert list(axis.values) == [r[key] for r in rows], name
    for (amp, d0), r in zip(AMPLITUDES, rows, strict=True):
        # the wave's overlap stays in Hertz's small-strain range (<= 1e-3 d)
        assert r["strain_max"] <= 1e-3
        if d0 > 0:
            assert r["strain_max"] / d0 == pytest.approx(amp)
            # the KdV width: the crossing extent (W/2) ln(1/SEPARATION), W = √(2δ0/ξ_m)
            if amp <= 0.09:
                w = math.sqrt(2 / amp)
                assert r["crossing"] == pytest.approx(w / 2 * math.log(1e4), rel=0.02)
    # the widest wave (strain/δ0 = 1e-3) needs the longest chain: ~2,900 | 2,500 grains
    assert rows[0]["n_left"] > 2500 and rows[0]["n_right"] > 2000


@pytest.fixture(scope="module")
def reduced(tmp_path_factory):
    spec = load_sweep_spec(SPEC)
    keep = [j for j, (a, _) in enumerate(AMPLITUDES) if a in (0.09, math.inf)]
    axes = tuple(dataclasses.replace(a, values={"alpha_rho_R": (0.5, 2.0),
                                                "alpha_kn_R": (1.0,)}[a.name])
                 if a.name in ("alpha_rho_R", "alpha_kn_R")
                 else dataclasses.replace(a, values=tuple(a.values[j] for j in keep))
                 for a in spec.axes)
    spec = dataclasses.replace(spec, axes=axes, _points=[])
    out = tmp_path_factory.mktemp("validity")
    # no point function given: [base.models] asks for every model (compare_point)
    outcome = run_sweep(spec, out=out, workers=1, processes=False, progress=False,
                        warmup=None)
    return outcome, read_results(outcome.table)


def test_sweeps_run_every_model_when_the_base_asks_for_them():
    spec = load_sweep_spec(SPEC)
    assert default_point_function(spec) == MODELS_POINT_FUNCTION
    plain = dataclasses.replace(spec, base={k: v for k, v in spec.base.items()
                                            if k != "models"}, _points=[])
    assert default_point_function(plain) == DEFAULT_POINT_FUNCTION
    tiny = load_sweep_spec(files("hertzchain") / "sweeps" / "tiny.toml")
    assert default_point_function(tiny) == DEFAULT_POINT_FUNCTION
    # a continuum switched on by an axis also asks for every model
    axis = Axis("models.continuum", "continuum", (False, "auto"))
    assert default_point_function(dataclasses.replace(
        plain, axes=(*plain.axes, axis), _points=[])) == MODELS_POINT_FUNCTION


def test_reduced_validity_sweep_records_every_model(reduced):
    outcome, res = reduced
    assert outcome.n_failed == 0 and len(res) == 4
    assert set(res["status"]) == {"ok"}
    assert set(res["point_function"]) == {"hertzchain.compare:compare_point"}
    amp = res["incident_strain_over_delta0"]
    pre = np.isfinite(amp)
    # the exact wave of strain 9e-5 d at δ0/d = 1e-3 (the paper's v0 = 1 m/s wave)
    assert np.allclose(amp[pre], 0.09, rtol=1e-9), amp
    assert set(res["continuum_model"][pre]) == {"eq4"}
    assert set(res["continuum_model"][~pre]) == {"eq7"}
    assert not any(res["continuum_note"]) and not any(res["theory_note"])
    assert np.all(np.isinf(amp[~pre])) and (~pre).sum() == 2
    cont, th = res["continuum_error"], res["theory_error"]
    assert np.all(np.isfinite(cont)) and np.all(np.isfinite(th))
    # Eq. 4 regime: both models within 1 % (the accuracy tests bound Eq. 4 to
    # 5e-3 in energy); sonic vacuum: within 10 % but not within 1 %
    assert np.all(cont[pre] <= THRESHOLDS[0]) and np.all(th[pre] <= THRESHOLDS[0])
    assert np.all((cont[~pre] > THRESHOLDS[0]) & (cont[~pre] <= THRESHOLDS[1]))
    assert np.all((th[~pre] > THRESHOLDS[0]) & (th[~pre] <= THRESHOLDS[1]))


def test_validity_summary_and_figure(reduced, tmp_path):
    _, res = reduced
    rows = validity_summary(res)
    by = {(r["model"], r["strain_over_delta0"]): r for r in rows}
    assert {m for m, _ in by} == {"continuum", "theory"}
    for model in ("continuum", "theory"):
        sv = by[(model, math.inf)]
        assert sv["n"] == 2 and sv["within_1"] == 0 and sv["within_10"] == 2
        (pre,) = [r for (m, a), r in by.items() if m == model and math.isfinite(a)]
        assert pre["within_1"] == 2 and pre["max_error"] <= THRESHOLDS[0]
    written = save_sweep_figures(res, tmp_path / "map.png")
    validity = [p for p in written if p.name == "validity_map.png"]
    assert validity and validity[0].stat().st_size > 10_000


def test_reproduce_item_quick(tmp_path, monkeypatch):
    # the report's coarse map (``--quick``), cut to one interface here
    from hertzchain.report import Report
    from hertzchain.reproduce import ITEMS, validity
    from hertzchain.reproduce.common import Context

    assert "validity" in ITEMS
    monkeypatch.setitem(validity.QUICK, "alpha_rho", (2.0,))
    monkeypatch.setitem(validity.QUICK, "alpha_kn", (0.5,))
    monkeypatch.setitem(validity.QUICK, "amplitudes", (0.09, math.inf))
    ctx = Context(tmp_path, progress=False)
    table = validity.run(ctx)
    assert len(table) == 2
    data = validity.to_json(table)
    pre, sv = data["points"]
    assert pre["delta0_over_d"] == pytest.approx(1e-3) and sv["delta0_over_d"] == 0.0
    assert pre["continuum_error"] <= THRESHOLDS[0] < sv["continuum_error"] <= THRESHOLDS[1]
    assert sv["incident_strain_over_delta0"] is None  # inf in JSON: the sonic vacuum
    figs = validity.figures(ctx, table)
    assert figs[0][0].exists()
    rep = Report("t")
    validity.report(rep, table, figs)
    text = rep.to_markdown(tmp_path)
    assert "within 10 %" in text and "sonic vacuum" in text
    assert "continuum (Eq. 4)" in text and "continuum (Eq. 7)" in text
    # one small file per point (scenario and row; the runs are compared in memory,
    # not written), and a second run reuses them: the same table, bit for bit
    assert sorted(p.name.split("-")[:2] == ["validity", "point"] for p in ctx.computed) \
        == [True, True] and sorted(ctx.runs.iterdir()) == sorted(ctx.computed)
    ctx2 = Context(tmp_path, progress=False)
    again = validity.run(ctx2)
    assert not ctx2.computed and sorted(ctx2.reused) == sorted(ctx.computed)
    assert json.dumps(validity.to_json(again)) == json.dumps(data)


@pytest.mark.parametrize("mode", ["quick", "full"])
def test_reproduce_maps_are_points_of_the_shipped_sweep(mode, tmp_path):
    # --quick and --full run a subset of the shipped map's points (the 175-point map
    # itself is ``hertzchain sweep model_validity``, ~1 h): every axis value is one of the
    # sweep's (the sweep's logspace ratios to round-off: 2.0 vs 10**(log10(4)/2)...)
    from hertzchain.reproduce import validity
    from hertzchain.reproduce.common import Context

    sub = validity.FULL if mode == "full" else validity.QUICK
    ctx = Context(tmp_path, mode=mode, progress=False)
    points = validity._points(ctx)
    assert len(points) == (len(sub["alpha_rho"]) * len(sub["alpha_kn"])
                           * len(sub["amplitudes"]))
    shipped = load_sweep_spec(SPEC).points()
    for p in points:
        same = [q for q in shipped if q.values.keys() == p.values.keys()
                and all(np.isclose(q.values[k], v, rtol=1e-12, atol=0)
                        for k, v in p.values.items())]
        assert len(same) == 1, p.label()
    amps = sorted({float(p.scenario.initial.strain_max / p.scenario.chain.delta0_over_d)
                   if p.scenario.chain.delta0_over_d else math.inf for p in points})
    assert amps == pytest.approx(sorted(sub["amplitudes"]))
