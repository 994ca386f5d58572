"""Sweep specifications: expansion, ids, and one clear error per class of bad input."""

import copy
from importlib.resources import files

import pytest

from hertzchain.cache import param_hash
from hertzchain.sweep import SweepError, load_sweep_spec, parse_sweep_spec


def spec_dict():
    return {
        "name": "t",
        "base": {
            "chain": {"delta0_over_d": 1e-3,
                      "sections": [{"n": 60}, {"n": 60, "alpha_rho": 1.0}]},
            "initial": {"kind": "exact_wave", "center": 20, "velocity_max": 0.05},
            "run": {"t_end": 1e-4},
        },
        "sweep": {"axes": [
            {"path": "chain.sections.1.alpha_rho", "name": "ar", "values": [0.5, 2.0]},
            {"path": "chain.sections.1.alpha_kn", "logspace": [0.2, 5.0, 3]},
        ]},
    }


def test_product_expansion_and_ids():
    spec = parse_sweep_spec(spec_dict())
    points = spec.points()
    assert spec.shape == (2, 3) and spec.n_points == 6 and len(points) == 6
    assert [p.index for p in points] == list(range(6))
    # last axis fastest; logspace end points exact; middle is the geometric mean
    kn = [p.values["chain.sections.1.alpha_kn"] for p in points[:3]]
    assert kn[0] == 0.2 and kn[2] == 5.0 and kn[1] == pytest.approx(1.0)
    assert points[4].values["ar"] == 2.0
    assert points[4].scenario.chain.sections[1].alpha_rho == 2.0
    assert points[4].id == param_hash(points[4].scenario.to_dict())
    assert len({p.id for p in points}) == 6
    # ids depend only on the scenario: an equivalent spec gives the same ids
    again = parse_sweep_spec(copy.deepcopy(spec_dict()))
    assert [p.id for p in again.points()] == [p.id for p in points]


def test_zip_mode_and_linspace_and_integer_axis():
    d = spec_dict()
    d["sweep"] = {"mode": "zip", "axes": [
        {"path": "chain.sections.0.n", "linspace": [60, 80, 3], "integer": True},
        {"path": "initial.velocity_max", "values": [0.01, 0.02, 0.01]},
    ]}
    spec = parse_sweep_spec(d)
    pts = spec.points()
    assert spec.shape == (3,)
    assert [p.scenario.chain.sections[0].n for p in pts] == [60, 70, 80]
    assert all(isinstance(p.values["chain.sections.0.n"], int) for p in pts)


def test_linked_axis_moves_with_its_leader():
    # one dimension of the product sets several keys (the model-validity amplitudes set
    # delta0, the wave's strain and the chain's size together); a linked axis may repeat
    # a value as long as the tuples differ
    d = spec_dict()
    d["sweep"]["axes"] += [
        {"path": "chain.delta0_over_d", "name": "d0", "values": [1e-3, 1e-3, 1e-4]},
        {"path": "initial.velocity_max", "with": "d0", "values": [0.01, 0.05, 0.05]},
        {"path": "chain.sections.0.n", "with": "d0", "values": [60, 70, 80]}]
    spec = parse_sweep_spec(d)
    assert spec.shape == (2, 3, 3) and spec.n_points == 18
    pts = spec.points()
    assert len(pts) == 18 and len({p.id for p in pts}) == 18
    rows = {(1e-3, 0.01): 60, (1e-3, 0.05): 70, (1e-4, 0.05): 80}
    seen = [(p.scenario.chain.delta0_over_d, p.scenario.initial.velocity_max,
             p.scenario.chain.sections[0].n) for p in pts]
    assert sorted(seen) == sorted([(*k, n) for k, n in rows.items()] * 6)
    # the last dimension (the leader and its linked axes) runs fastest
    assert [p.values["d0"] for p in pts[:3]] == [1e-3, 1e-3, 1e-4]
    assert spec.to_dict()["axes"][3]["with"] == "d0"


LINK = [{"path": "chain.delta0_over_d", "name": "d0", "values": [1e-3, 1e-4]}]


def test_linked_axis_errors_name_the_key():
    for axes, mode, message in (
            (LINK + [{"path": "initial.velocity_max", "with": "nope", "values": [0.1, 0.2]}],
             "product", "must name an earlier axis"),
            ([{"path": "initial.velocity_max", "with": "d0", "values": [0.1, 0.2]}] + LINK,
             "product", "must name an earlier axis"),
            (LINK + [{"path": "initial.velocity_max", "with": "d0", "values": [0.1]}],
             "product", "1 values, but that axis has 2"),
            (LINK + [{"path": "initial.velocity_max", "with": "d0", "values": [0.1, 0.2]}],
             "zip", "remove 'with'"),
            (LINK + [{"path": "initial.velocity_max", "with": "", "values": [0.1, 0.2]}],
             "product", "with must name an earlier axis"),
            ([{"path": "chain.delta0_over_d", "name": "d0", "values": [1e-3, 1e-3]},
              {"path": "initial.velocity_max", "with": "d0", "values": [0.1, 0.1]}],
             "product", "duplicate values")):
        d = spec_dict()
        d["sweep"] = {"mode": mode, "axes": axes}
        with pytest.raises(SweepError) as info:
            parse_sweep_spec(d)
        assert message in str(info.value), str(info.value)


def test_missing_tables_are_created():
    d = spec_dict()
    d["sweep"]["axes"] = [{"path": "record.energy_every", "values": [0, 10]}]
    pts = parse_sweep_spec(d).points()
    assert [p.scenario.record.energy_every for p in pts] == [0, 10]


@pytest.mark.parametrize("name", ["fig7_map.toml", "tiny.toml", "gamma_lines.toml",
                                  "amplitude_precompression.toml"])
def test_shipped_sweeps_are_valid(name):
    spec = load_sweep_spec(files("hertzchain") / "sweeps" / name)
    assert spec.n_points == len(spec.points()) >= 4


def test_shipped_sweeps_by_name(monkeypatch, tmp_path):
    from hertzchain.sweep import shipped_sweeps

    assert {"fig7_map", "tiny", "gamma_lines", "amplitude_precompression"} <= set(
        shipped_sweeps())
    monkeypatch.chdir(tmp_path)
    assert load_sweep_spec("tiny").name == "tiny"
    assert load_sweep_spec("tiny.toml").n_points == 4
    with pytest.raises(SweepError, match=r"shipped sweeps: \['amplitude_precompression'"):
        load_sweep_spec("nope")
    (tmp_path / "tiny.toml").write_text("[sweep\n")  # a local file wins
    with pytest.raises(SweepError, match="not valid TOML"):
        load_sweep_spec("tiny.toml")


def test_fig7_map_is_the_acceptance_grid():
    spec = load_sweep_spec(files("hertzchain") / "sweeps" / "fig7_map.toml")
    assert spec.shape == (21, 21)
    for axis in spec.axes:
        assert axis.values[0] == 0.2 and axis.values[-1] == 5.0
    assert spec.points()[0].scenario.chain.delta0_over_d == 1e-3


def _edit(fn):
    d = spec_dict()
    fn(d)
    return d


def _axis(**kw):
    return lambda d: d["sweep"]["axes"].__setitem__(0, kw)


BAD = [
    ("unknown top key", lambda d: d.update(sweeps={}), "unknown key(s) ['sweeps']"),
    ("unknown sweep key", lambda d: d["sweep"].update(axis=[]), "unknown key(s) ['axis']"),
    ("bad mode", lambda d: d["sweep"].update(mode="grid"), "mode = 'grid'"),
    ("no base", lambda d: d.pop("base"), "[base] is required"),
    ("invalid base", lambda d: d["base"]["chain"].update(diameter=-1), "[base] is not a valid"),
    ("no sweep", lambda d: d.pop("sweep"), "[sweep] is required"),
    ("no axes", lambda d: d["sweep"].update(axes=[]), "axes is required"),
    ("axis not a table", lambda d: d["sweep"]["axes"].__setitem__(0, 3), "must be a table"),
    ("unknown axis key", _axis(path="chain.delta0_over_d", value=[1]), "unknown key(s) ['value']"),
    ("missing path", _axis(values=[1]), "path is required"),
    ("two sources", _axis(path="chain.delta0_over_d", values=[0.001], linspace=[0, 1, 2]),
     "exactly one of values"),
    ("no source", _axis(path="chain.delta0_over_d"), "exactly one of values"),
    ("empty axis", _axis(path="chain.delta0_over_d", values=[]), "the axis is empty"),
    ("values not list", _axis(path="chain.delta0_over_d", values=0.1), "values must be a list"),
    ("nested value", _axis(path="chain.delta0_over_d", values=[[1]]), "values must be finite"),
    ("logspace <= 0", _axis(path="chain.delta0_over_d", logspace=[0, 1e-3, 3]),
     "logspace bounds must be > 0"),
    ("linspace n", _axis(path="chain.delta0_over_d", linspace=[0, 1e-3, 0]),
     "count n must be an integer >= 1"),
    ("linspace shape", _axis(path="chain.delta0_over_d", linspace=[0, 1e-3]),
     "linspace must be [lo, hi, n]"),
    ("n = 1 range", _axis(path="chain.delta0_over_d", linspace=[0, 1e-3, 1]), "needs lo == hi"),
    ("integer flag", _axis(path="chain.sections.0.n", values=[60], integer="yes"),
     "integer must be true or false"),
    ("integer strings", _axis(path="chain.sections.0.n", values=["a"], integer=True),
     "integer = true needs numeric"),
    ("duplicate values", _axis(path="chain.sections.0.n", values=[60, 60.2], integer=True),
     "duplicate values"),
    ("reserved name", _axis(path="chain.delta0_over_d", name="status", values=[1e-3]),
     "reserved column"),
    ("malformed path", _axis(path="chain..delta0_over_d", values=[1e-3]), "malformed"),
    ("index out of range", _axis(path="chain.sections.5.alpha_rho", values=[1.0]),
     "index 5 out of range"),
    ("list needs index", _axis(path="chain.sections.first.n", values=[60]),
     "expected a 0-based index, got 'first'"),
    ("through a value", _axis(path="chain.delta0_over_d.x", values=[1]), "is a value"),
    ("index a missing list", _axis(path="chain.segments.0.n", values=[1]), "does not exist"),
    ("typo in key", _axis(path="chain.sections.1.alpha_rhoo", values=[1.0]),
     "unknown key 'alpha_rhoo' in [chain.sections[1]]; did you mean 'alpha_rho'"),
    ("invalid point value", _axis(path="chain.sections.1.alpha_rho", values=[1.0, -2.0]),
     "point 3 (chain.sections.1.alpha_rho=-2.0, "),
    ("overlapping paths", lambda d: d["sweep"]["axes"].append(
        {"path": "chain.sections.1", "values": [1]}), "overlap"),
    ("duplicate names", lambda d: d["sweep"]["axes"].append(
        {"path": "chain.delta0_over_d", "name": "ar", "values": [1e-3]}), "must be unique"),
    ("zip lengths", lambda d: d["sweep"].update(mode="zip"), "equal length"),
    ("zip duplicate points", lambda d: d["sweep"].update(mode="zip", axes=[
        {"path": "chain.sections.1.alpha_rho", "values": [0.5, 0.5]}]), "same scenario"),
]


@pytest.mark.parametrize(("case", "edit", "message"), BAD, ids=[b[0] for b in BAD])
def test_bad_specs_name_the_problem(case, edit, message):
    with pytest.raises(SweepError) as info:
        parse_sweep_spec(_edit(edit))
    assert message in str(info.value), str(info.value)


def test_many_invalid_points_are_summarised():
    d = spec_dict()
    d["sweep"]["axes"] = [{"path": "chain.sections.1.alpha_rho",
                           "values": [-1.0, -2.0, -3.0, -4.0, -5.0, -6.0, -7.0, 1.0]}]
    with pytest.raises(SweepError, match=r"7 of 8 sweep points are invalid.*\(and 2 more\)"):
        parse_sweep_spec(d)


def test_file_errors(tmp_path):
    with pytest.raises(SweepError, match="not found"):
        load_sweep_spec(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[sweep\n")
    with pytest.raises(SweepError, match="not valid TOML"):
        load_sweep_spec(bad)
    typo = tmp_path / "typo.toml"
    typo.write_text('[base.chain]\nsections = [{n = 5}]\n[base.run]\nt_end = 1e-4\n'
                    '[sweep]\n[[sweep.axes]]\npath = "chain.sections.0.nn"\nvalues = [1]\n')
    with pytest.raises(SweepError,
                       match=r"(?s)typo.toml: .*unknown key 'nn' in .*did you mean 'n'"):
        load_sweep_spec(typo)
