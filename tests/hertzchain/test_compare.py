"""hertzchain compare: the comparison object, its files, and the comparison checked.

Tolerances are stated where they are used.  The accuracy of the continuum against the
discrete chain on the paper's cases is in ``test_compare_accuracy.py``.
"""

import json
import math

import h5py
import numpy as np
import pytest

from hertzchain.cli import main
from hertzchain.compare import FORMAT, analyse, compare, read_comparison, validity_word
from hertzchain.models import run
from hertzchain.scenario import parse_scenario

MONO = {
    "name": "mono-two-section",
    "chain": {"delta0_over_d": 1e-3, "sections": [{"n": 200}, {"n": 200}]},
    "initial": {"kind": "exact_wave", "center": 100, "velocity_max": 0.0822},
    "run": {"t_end": 1.0e-3},
    "models": {"continuum": "auto", "nodes_per_grain": 3, "samples": 21},
}


@pytest.fixture(scope="module")
def mono(tmp_path_factory):
    out = tmp_path_factory.mktemp("mono")
    return out, compare(parse_scenario(MONO), out=out)


def test_monodisperse_chain_gives_zero_transmitted_and_reflected_difference(mono):
    # Two identical sections: nothing is scattered.  The theory says E_T = 1, E_R = 0
    # exactly; the exact discrete solitary wave crosses with no reflection (its energy
    # left behind is the sampling residual, ~1e-12 of the peak); the continuum, started
    # from the same grains, sheds a small tail while adapting (measured ~2e-6 of E_in).
    _, cmp = mono
    th = cmp.differences["theory"]
    assert th["Et_tr"][1] == pytest.approx(1.0, abs=1e-14)
    assert th["Et_re"][1] == pytest.approx(0.0, abs=1e-14)
    assert abs(th["Et_tr"][2]) < 1e-6 and abs(th["Et_re"][2]) < 1e-6
    c = cmp.differences["continuum"]
    assert abs(c["Et_tr"][2]) < 1e-4 and abs(c["Et_re"][2]) < 1e-4
    # no reflected wave in any model
    for s in cmp.series.values():
        assert not np.isfinite(s.fronts["reflected"]).any()
    assert not np.isfinite(cmp.run.theory.fronts(cmp.times)["reflected"]).any()
    assert cmp.run.theory.classes()["region"].startswith("origin") or \
        cmp.run.theory.gamma_rg == pytest.approx(1.0)
    # the front speeds agree with the theory's (the exact wave: to the fit's accuracy)
    assert abs(th["speed_transmitted"][2]) < 2e-3
    assert abs(cmp.differences["continuum"]["speed_transmitted"][2]) < 2e-3


def test_files_carry_every_model_and_the_parameters(mono):
    out, cmp = mono
    path = out / "compare.h5"
    with h5py.File(path, "r") as f:
        assert f.attrs["format"] == FORMAT
        assert json.loads(f.attrs["scenario"])["name"] == "mono-two-section"
        assert {"discrete", "continuum", "theory", "comparison"} <= set(f)
        for name in ("discrete", "continuum"):
            g = f[name]
            assert g["t"].shape == (21,)
            assert g["v"].shape == (len(cmp.display), 400)
            assert set(g["fronts"]) == {"incident", "transmitted", "reflected"}
            assert json.loads(g.attrs["params"])
            assert g.attrs["completed"]
        assert "partition" in f["theory"]
        assert f["comparison"].attrs["verdict"] == cmp.verdict()
    numbers = read_comparison(path)
    assert numbers["errors"]["continuum"]["error"] == pytest.approx(
        cmp.errors["continuum"]["error"])
    for name in ("profiles.png", "fronts.png", "energy.png", "report.md", "report.html"):
        assert (out / name).stat().st_size > 1000, name
    text = (out / "report.md").read_text()
    assert cmp.verdict() in text and "Differences to the discrete chain" in text
    # no temporary files left behind (atomic writes)
    assert not list(out.glob(".*tmp"))


def test_verdict_words():
    assert validity_word(0.004) == "within 1 %"
    assert validity_word(0.05) == "within 10 %"
    assert validity_word(0.3) == "off by 30 %"
    assert validity_word(math.nan) == "not compared"


def test_verdict_phrases_an_unmeasured_error_separately():
    # a NaN error is "could not be compared", never "not compared of ... (nan%)"
    from hertzchain.compare import _verdict_part

    nan = math.nan
    text = _verdict_part("the theory", {"energy": nan, "speed": nan, "error": nan}, False)
    assert text == ("the theory could not be compared with the discrete chain (no front "
                    "speed difference: a wave front or an energy was not found in one of "
                    "the models)")
    text = _verdict_part("X", {"energy": nan, "speed": nan, "error": nan}, True)
    assert "no energy and no transmitted speed difference" in text and "nan" not in text
    text = _verdict_part("X", {"energy": 2e-3, "speed": nan, "error": 2e-3}, True)
    assert text == ("X is within 1 % of the discrete chain (energy 2.0e-03; transmitted "
                    "speed not measured)")
    text = _verdict_part("X", {"energy": 0.2, "speed": 0.05, "error": 0.2}, True)
    assert text == ("X is off by 20 % of the discrete chain (energy 2.0e-01, transmitted "
                    "speed 5.0%)")


def test_cli_compare_json_and_exit_status(tmp_path, capsys, monkeypatch):
    toml = tmp_path / "mono.toml"
    toml.write_text("""name = "cli-mono"
[chain]
delta0_over_d = 1e-3
[[chain.sections]]
n = 200
[[chain.sections]]
n = 200
alpha_rho = 2.0
[initial]
kind = "exact_wave"
center = 100
velocity_max = 0.0822
[run]
t_end = 3e-4
[models]
samples = 7
""")
    assert main(["compare", str(toml), "--out", str(tmp_path / "c"), "--json",
                 "--continuum", "off"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert "theory" in data["errors"] and "continuum" not in data["errors"]
    assert data["theory"]["gamma_rg"] == pytest.approx(2 ** 0.5)
    # a continuum that fails is reported, not compared, and the exit status says so
    import continuum

    def boom(*args, **kwargs):
        raise FloatingPointError("overflow (test)")

    monkeypatch.setattr(continuum, "run", boom)
    assert main(["compare", str(toml), "--out", str(tmp_path / "d"),
                 "--continuum", "eq4"]) == 3  # EXIT_INCOMPLETE
    captured = capsys.readouterr()
    assert "did not complete" in captured.out and "overflow (test)" in captured.err
    assert "did not complete" in (tmp_path / "d" / "report.md").read_text()


def test_analyse_without_continuum_and_without_interface():
    sc = parse_scenario({"chain": {"delta0_over_d": 1e-3, "sections": [{"n": 300}]},
                         "initial": {"kind": "exact_wave", "center": 100,
                                     "velocity_max": 0.0822},
                         "run": {"t_end": 3e-4}, "models": {"samples": 9}})
    cmp = analyse(run(sc, samples=True))
    assert cmp.run.interface is None
    assert set(cmp.errors) == {"theory"}
    # one section: the theory is the incident speed (Nesterenko at the wave's amplitude)
    assert cmp.errors["theory"]["speed"] < 2e-3
    assert "theory" in cmp.verdict()
