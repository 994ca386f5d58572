"""Phase-diagram figures and the theory-agreement band, from synthetic results tables."""

import functools
import json

import numpy as np
import pytest

import theory
from hertzchain.sweep import (
    classification_agreement,
    parse_sweep_spec,
    predicted_labels,
    read_results,
    run_point,
    write_table,
)
from hertzchain.sweep.cli import main as sweep_main
from hertzchain.sweep.synthetic import synthetic_point
from hertzchain.sweep_plot import (
    classification_codes,
    plot_cut,
    plot_phase_map,
    save_sweep_figures,
)


def grid_spec(n=11, lo=0.2, hi=5.0):
    return parse_sweep_spec({
        "name": "synthetic-map",
        "base": {"chain": {"delta0_over_d": 1e-3, "sections": [{"n": 60}, {"n": 60}]},
                 "initial": {"kind": "exact_wave", "center": 20, "velocity_max": 0.05},
                 "run": {"t_end": 1e-4}},
        "sweep": {"axes": [
            {"path": "chain.sections.1.alpha_rho", "logspace": [lo, hi, n]},
            {"path": "chain.sections.1.alpha_kn", "logspace": [lo, hi, n]},
        ]},
    })


def synthetic_table(path, spec, *, band=0.0, fail_above=None, pending=0):
    """Write results.h5 without Dask: run the synthetic point function in-process."""
    fn = functools.partial(synthetic_point, band=band, fail_above=fail_above)
    points = spec.points()
    records = {p.id: json.loads(json.dumps(run_point(fn, p.scenario, p.id, p.values)))
               for p in points[: len(points) - pending]}
    return write_table(path / "results.h5", spec, points, records)


def test_predicted_labels_follow_eqs_9_and_13():
    t, r = predicted_labels([0.2, 5.0, 1.0, 0.5], [1.0, 1.0, 1.0, 0.5**1.5])
    assert list(t) == ["fracture", "squeeze", "none", "none"]
    assert list(r) == ["expansive", "compressive", "none", "expansive"]


def test_fission_parameter():
    from hertzchain.sweep import fission_parameter

    assert fission_parameter(1.0, 1.0) == pytest.approx(1.0)
    a_r, a_k = theory.alphas_from_gammas(1.3, 1.0)  # on gamma_RG = 1: q = gamma_c0
    assert fission_parameter(a_r, a_k) == pytest.approx(1.3)
    a_r, a_k = theory.alphas_from_gammas(np.sqrt(1.5), 0.5)  # q = 1 off gamma_c0 = 1
    assert fission_parameter(a_r, a_k) == pytest.approx(1.0)
    assert fission_parameter(np.array([0.5, 2.0]), np.array([1.0, 1.0])).shape == (2,)


def test_agreement_is_total_without_a_band(tmp_path):
    res = read_results(synthetic_table(tmp_path, grid_spec()))
    agr = classification_agreement(res)
    assert agr.n_classified == 121
    assert agr.fraction_agree == 1.0 and agr.band_gamma_c0 == 0 and agr.band_gamma_rg == 0
    assert agr.disagreeing == []
    # 11 log-spaced values with 1 in the middle: points on γ_c0 = 1 need α_kn = α_ρ^1.5
    # 11 values spaced ln(25)/10 with 1 in the middle: γ_c0 = 1 needs α_kn = α_ρ^1.5, i.e.
    # steps (i, 1.5 i) for i = -2, 0, 2
    assert agr.n_on_line_c0 == 3 and agr.on_line_labels["gamma_c0=1"] == {"none": 3}
    assert agr.n_on_line_rg == 3


def test_points_on_the_lines(tmp_path):
    """A classifier that picks a side on γ_c0 = 1 agrees unless the lines are strict."""
    res = read_results(synthetic_table(tmp_path, grid_spec()))
    on = np.abs(np.log(res["gamma_c0"])) < 1e-9
    res.columns["transmitted"] = np.where(on, "squeeze", res["transmitted"]).astype(object)
    agr = classification_agreement(res)
    assert agr.fraction_agree == 1.0 and agr.on_line_labels["gamma_c0=1"] == {"squeeze": 3}
    strict = classification_agreement(res, strict_lines=True)
    assert strict.fraction_agree == pytest.approx(118 / 121)
    assert strict.band_gamma_c0 < 1e-9 and len(strict.disagreeing) == 3


def test_agreement_measures_the_band(tmp_path):
    """The synthetic classifier says "none" within |ln γ| < 0.3: the band found is the
    largest sampled |ln γ| below 0.3, and everything outside it agrees."""
    spec = grid_spec(21)
    res = read_results(synthetic_table(tmp_path, spec, band=0.3, fail_above=4.0))
    agr = classification_agreement(res)
    assert agr.n_classified == int(res.ok.sum()) < 441
    assert 0.3 - agr.grid_step_gamma_c0 <= agr.band_gamma_c0 <= 0.3
    assert 0.3 - agr.grid_step_gamma_rg <= agr.band_gamma_rg <= 0.3
    assert 0 < agr.fraction_agree < 1
    lc = np.abs(np.log(res["gamma_c0"][res.ok]))
    outside = lc > agr.band_gamma_c0
    assert np.all(res["transmitted"][res.ok][outside] != "none")
    for d in agr.disagreeing:
        lc = abs(np.log(float(theory.gamma_c0(d["alpha_rho"], d["alpha_kn"]))))
        lr = abs(np.log(float(theory.gamma_rg(d["alpha_rho"], d["alpha_kn"]))))
        assert lc <= agr.band_gamma_c0 or lr <= agr.band_gamma_rg
    assert set(agr.band_gamma_c0_by_side) == {"gamma_RG<1", "gamma_RG>1"}
    assert set(agr.band_gamma_rg_by_side) == {"gamma_c0<1", "gamma_c0>1"}
    assert max(agr.band_gamma_c0_by_side.values()) <= agr.band_gamma_c0
    assert min(agr.band_gamma_c0_by_side.values()) > 0.3 - 2 * agr.grid_step_gamma_c0
    assert "disagreement band around gamma_c0 = 1" in agr.summary()
    assert set(agr.band_fission) == {"q>1", "q<1"} and 0 < agr.fraction_agree_fission < 1
    json.dumps(agr.to_dict())


def test_classification_codes(tmp_path):
    res = read_results(synthetic_table(tmp_path, grid_spec(5), band=0.01, fail_above=3.0,
                                       pending=2))
    codes = classification_codes(res)
    assert set(codes[res["status"] == "failed"]) == {5}
    assert list(codes[-2:]) == [6, 6]
    ok = res.ok
    region = {"I": 0, "II": 1, "III": 2, "IV": 3}
    for code, reg in zip(codes[ok], res["theory_region"][ok], strict=True):
        assert code == region.get(reg, 4)


def test_plot_phase_map_draws_on_given_axes(tmp_path):
    from matplotlib.figure import Figure

    res = read_results(synthetic_table(tmp_path, grid_spec(7), band=0.05))
    fig = Figure()
    ax = fig.subplots()
    plot_phase_map(ax, res)
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    assert ax.collections  # the colour mesh and the contours
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("gamma_{c_0}=1" in lab for lab in labels)
    assert any("measured Ek_re" in lab for lab in labels)
    assert any("fission" in lab for lab in labels)
    fig2 = Figure()
    assert plot_cut(fig2.subplots(), res, along="alpha_kn", quantities=("Ek_re", "Et_re"))


def test_plot_sweep_cli_writes_pngs(tmp_path, capsys):
    synthetic_table(tmp_path, grid_spec(9), band=0.1, fail_above=4.0, pending=3)
    assert sweep_main(["plot-sweep", str(tmp_path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [p.rsplit("/", 1)[-1] for p in out["figures"]] == ["phase_map.png",
                                                              "phase_map-cuts.png"]
    for p in out["figures"]:
        with open(p, "rb") as fh:
            assert fh.read(8) == b"\x89PNG\r\n\x1a\n"
    assert out["agreement"]["n_classified"] > 0
    target = tmp_path / "figs" / "map.png"
    assert sweep_main(["plot-sweep", str(tmp_path / "results.h5"), "--out", str(target),
                       "--energy", "Et_re"]) == 0
    text = capsys.readouterr().out
    assert "wrote" in text and "agree with theory" in text
    assert target.exists() and (tmp_path / "figs" / "map-cuts.png").exists()


def test_non_alpha_sweep_is_drawn_on_its_own_axes(tmp_path):
    spec = parse_sweep_spec({
        "base": {"chain": {"delta0_over_d": 1e-3,
                           "sections": [{"n": 60}, {"n": 60, "alpha_rho": 0.5}]},
                 "initial": {"kind": "exact_wave", "center": 20, "velocity_max": 0.05},
                 "run": {"t_end": 1e-4}},
        "sweep": {"axes": [{"path": "chain.delta0_over_d", "logspace": [1e-4, 1e-2, 3]},
                           {"path": "initial.velocity_max", "values": [0.01, 0.1]}]},
    })
    res = read_results(synthetic_table(tmp_path, spec))
    written = save_sweep_figures(res)
    assert [p.name for p in written] == ["phase_map.png"]


def test_read_results_rejects_other_files(tmp_path):
    import h5py

    with h5py.File(tmp_path / "other.h5", "w") as fh:
        fh.attrs["format"] = "something-else"
    with pytest.raises(ValueError, match="not a hertzchain sweep results table"):
        read_results(tmp_path / "other.h5")
    with pytest.raises(FileNotFoundError):
        read_results(tmp_path / "missing")
