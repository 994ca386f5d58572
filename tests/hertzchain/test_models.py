"""The [models] table and the one run path (hertzchain.models.run)."""

import dataclasses
import math
import re

import numpy as np
import pytest

import theory
from hertzchain import models as M
from hertzchain.runner import run_scenario
from hertzchain.scenario import (
    SCHEMA,
    ScenarioError,
    load_scenario,
    model_applies,
    parse_scenario,
    schema_markdown,
    shipped_scenarios,
)


def scenario(ar=0.5, ak=2.0, *, models=None, n=(150, 250), t_end=6e-4, d0=1e-3, center=75,
             **extra):
    data = {"name": "models-test",
            "chain": {"delta0_over_d": d0, "sections": [{"n": n[0]},
                                                        {"n": n[1], "alpha_rho": ar,
                                                         "alpha_kn": ak}]},
            "initial": {"kind": "exact_wave", "center": center,
                        "velocity_max": 0.0822 if d0 else 0.6},
            "run": {"t_end": t_end}, "models": models or {}, **extra}
    return parse_scenario(data)


# -- [models] ---------------------------------------------------------------------------
def test_models_defaults_and_auto():
    sc = scenario()
    assert sc.models.theory is None and sc.models.continuum is None  # not given
    assert sc.with_default_models().models.names == ("discrete", "theory")
    assert sc.with_default_models(compare=True).models.names == ("discrete", "continuum",
                                                                 "theory")
    assert sc.models.continuum_model(sc.chain) is None
    auto = scenario(models={"continuum": "auto"})
    assert auto.models.continuum_model(auto.chain) == "eq4"
    assert scenario(models={"continuum": True}).models.continuum == "auto"
    sonic = scenario(d0=0.0, models={"continuum": "auto"})
    assert sonic.models.continuum_model(sonic.chain) == "qc"
    with pytest.raises(TypeError, match="chain must be a ChainSpec"):
        auto.models.continuum_model(1e-3)


def test_continuum_integrator_and_its_order_alias():
    """[models] integrator names the continuum's splitting method (theory.splitting);
    the deprecated order picks the drift-first method it always named; not given, both
    integrator and dt_safety are the model's own (ModelsSpec.continuum_step)."""
    m = scenario(models={"continuum": "auto"}).models
    assert (m.integrator, m.order, m.dt_safety) == (None, None, None)  # not given
    assert scenario(models={"continuum": "auto", "order": 2}).models.continuum_step("eq4") \
        == ("position_verlet", 0.5)
    m = scenario(models={"continuum": "auto", "integrator": "blanes_moan4", "order": 4,
                         "dt_safety": 1.45}).models
    assert all(m.continuum_step(name) == ("blanes_moan4", 1.45) for name in ("eq4", "eq7", "qc"))
    again = parse_scenario(scenario(models={"continuum": "auto",
                                            "integrator": "verlet"}).to_input())
    assert again.models.continuum_step("qc") == ("verlet", 0.8)
    assert again.models.order is None and again.models.dt_safety is None  # still not given


def _step_scenario(models, *, d0=1e-3, drag=0.0, sections=2, strain=None):
    """A scenario for the step's checks: ``sections`` sections, optional drag; the exact
    wave set by its velocity or, with ``strain`` (strain/δ0), by ``strain_max``."""
    secs = [{"n": 150}, {"n": 250, "alpha_rho": 0.5, "alpha_kn": 2.0}][:sections]
    amp = ({"strain_max": strain * d0} if strain is not None
           else {"velocity_max": 0.0822 if d0 else 0.6})
    return parse_scenario({
        "chain": {"delta0_over_d": d0, "drag": drag, "sections": secs},
        "initial": {"kind": "exact_wave", "center": 75, **amp},
        "run": {"t_end": 6e-4}, "models": models})


def test_each_model_owns_its_default_step():
    """Not given, [models] integrator and dt_safety are the model's own class attributes:
    Yoshida-4 drift first at 0.5 for Eq. 4 and Eq. 7 (the values every earlier version
    stepped them with, so their runs and cache keys are unchanged), position Verlet at
    0.8 for the quasi-continuum (docs/physics.md §24); KdV's key records Eq. 4's.  "auto"
    resolves them once its model is known: both regimes."""
    import continuum
    from theory.splitting import STABILITY_LIMITS

    own = {name: (cls.default_integrator, cls.default_dt_safety)
           for name, cls in continuum.MODELS.items()}
    assert own == {"eq4": ("position_yoshida4", 0.5), "eq7": ("position_yoshida4", 0.5),
                   "qc": ("position_verlet", 0.8)}
    for method, safety in own.values():  # each inside its method's stability limit
        assert 0 < 2 * safety < STABILITY_LIMITS[method]
    for name in ("eq4", "eq7", "qc"):
        m = scenario(models={"continuum": name}).models
        assert m.continuum_step(name) == own[name]
    kdv = _step_scenario({"continuum": "kdv"}, sections=1)
    assert kdv.models.continuum_step("kdv") == own["eq4"]
    # "auto" under precompression: the incident wave decides; the step follows the model
    sc = scenario(models={"continuum": "auto"})
    for s, name in ((0.09, "eq4"), (2.0, "eq7"), (100.0, "qc")):
        model = sc.models.continuum_model(sc.chain, s)
        assert model == name and sc.models.continuum_step(model) == own[name]
    assert sc.models.possible_continuum_models(sc.chain) == ("eq4", "eq7", "qc")
    # ... and in the sonic vacuum: the quasi-continuum, stepped at its own
    sonic = scenario(d0=0.0, models={"continuum": "auto"})
    assert sonic.models.possible_continuum_models(sonic.chain) == ("qc",)
    assert sonic.models.continuum_step("qc") == ("position_verlet", 0.8)
    # a chain the quasi-continuum does not fit: auto can run Eq. 4 and Eq. 7 only
    drag = _step_scenario({"continuum": "auto"}, drag=10.0)
    assert drag.models.possible_continuum_models(drag.chain) == ("eq4", "eq7")


def test_an_explicit_step_wins_and_is_range_checked():
    """A user's integrator or dt_safety wins over the model's own, and the resolved step
    is checked against the method's stability limit (ω_max Δt = 2 dt_safety < limit) for
    every model the continuum may run, with an error naming the key and the range."""
    m = scenario(models={"continuum": "qc", "dt_safety": 0.5,
                         "integrator": "position_yoshida4"}).models
    assert m.continuum_step("qc") == ("position_yoshida4", 0.5)
    assert scenario(models={"continuum": "qc", "dt_safety": 0.9}).models.continuum_step(
        "qc") == ("position_verlet", 0.9)  # position Verlet's limit: (0, 1)
    with pytest.raises(ScenarioError, match=r"\[models\] dt_safety = 1 is beyond the "
                       r"stability limit of integrator 'position_verlet': allowed \(0, 1\)"):
        scenario(models={"continuum": "qc", "dt_safety": 1.0})
    # qc's own 0.8 is beyond Yoshida-4's (0, 0.7865): named, with the key to set
    own = (r"\[models\] dt_safety \(not given: the own 0.8 of continuum 'qc'.*\) is beyond "
           r"the stability limit of integrator 'position_yoshida4': allowed \(0, 0.7865\)"
           r".*set \[models\] dt_safety in that range")
    with pytest.raises(ScenarioError, match=own):
        scenario(models={"continuum": "qc", "integrator": "position_yoshida4"})
    with pytest.raises(ScenarioError, match=own):
        scenario(models={"continuum": "qc", "order": 4})
    # "auto" under precompression may run qc (the strain is known only later): checked
    with pytest.raises(ScenarioError, match=r"not given: the own 0.8 of continuum 'qc', "
                       r"which continuum = 'auto' may run on this chain"):
        scenario(models={"continuum": "auto", "integrator": "position_yoshida4"})
    # ... when the continuum is not given, not at parsing (a discrete run must not import
    # the continuum), but where compare turns it on and resolves qc's step
    off = scenario(models={"integrator": "position_yoshida4"}).models
    with pytest.raises(ScenarioError, match=r"not given: the own 0.8 of continuum 'qc'"):
        off.continuum_step("qc")
    # where auto cannot run qc (drag), Yoshida-4 at Eq. 4/7's own 0.5 is fine
    drag = _step_scenario({"continuum": "auto", "integrator": "position_yoshida4"},
                          drag=10.0)
    assert drag.models.continuum_step("eq7") == ("position_yoshida4", 0.5)


def test_scenario_dict_of_a_step_not_given():
    """Scenario.to_dict (cache keys, sweep point ids) writes a step not given as what it
    resolves to where the scenario decides it, and None where the measured wave does:
    without a continuum and for Eq. 4/Eq. 7 (Yoshida-4, written None, at 0.5) their dicts
    are the earlier ones; qc is (position Verlet, 0.8), the dict of the validity map's qc
    points that named them; "auto" under precompression is (None, None) unless the
    wave's strain_max decides the model (never the dict of an explicit step)."""
    from hertzchain.scenario import STEP_KEY_DEFAULT

    assert STEP_KEY_DEFAULT == ("position_yoshida4", 0.5)
    pv = ("position_verlet", 0.8)
    cases = [({}, {}, (None, 0.5)), ({"continuum": False}, {}, (None, 0.5)),
             ({"continuum": "eq4"}, {}, (None, 0.5)), ({"continuum": "eq7"}, {}, (None, 0.5)),
             ({"continuum": "kdv"}, {"sections": 1}, (None, 0.5)),
             ({"continuum": "qc"}, {}, pv), ({"continuum": "auto"}, {"d0": 0.0}, pv),
             ({"continuum": "auto"}, {}, (None, None)),
             ({"continuum": "auto"}, {"strain": 0.09}, (None, 0.5)),
             ({"continuum": "auto"}, {"strain": 2.0}, (None, 0.5)),
             ({"continuum": "auto"}, {"strain": 9.0}, pv),
             ({"continuum": "auto"}, {"drag": 10.0}, (None, 0.5)),
             ({"continuum": "auto", "dt_safety": 0.5}, {}, (None, 0.5)),
             ({"continuum": "auto", "order": 2}, {}, (None, None)),
             ({"continuum": "qc", "integrator": "verlet"}, {}, ("verlet", 0.8))]
    for models, extra, want in cases:
        sc = _step_scenario(models, **extra)
        got = sc.to_dict()["models"]
        assert (got["integrator"], got["dt_safety"]) == want, (models, extra)
        back = parse_scenario(sc.to_input())  # the round trip keeps "not given"
        for key in ("integrator", "order", "dt_safety"):
            assert getattr(back.models, key) == models.get(key), (models, extra, key)
    # "auto" with and without an explicit 0.5 step differently where qc is picked
    assert _step_scenario({"continuum": "auto"}).to_dict() != _step_scenario(
        {"continuum": "auto", "dt_safety": 0.5}).to_dict()
    # a known strain narrows the check too: Yoshida-4 alone is fine for a weak wave
    weak = _step_scenario({"continuum": "auto", "integrator": "position_yoshida4"},
                          strain=0.09)
    assert weak.models.possible_continuum_models(weak.chain, 0.09) == ("eq4",)


def test_continuum_runs_with_blanes_moan():
    """The run path steps the continuum with the scenario's method and dt_safety: the
    result records them and, at 1.45 (Blanes–Moan-4 at 92 % of its limit, 2.9× the
    default's dt), is closer to a converged reference (Blanes–Moan-4 at 0.2) than the
    default (Yoshida-4 at 0.5).  Measured relative L2 of the final grain velocities:
    6.7e-7 against 3.9e-5; bounds 1e-5 and 10× better (a wrong merge of the FSAL kicks
    or a wrong dt is an O(1) or O(dt) error, far above both)."""
    kw = {"continuum": "eq4", "samples": 3, "nodes_per_grain": 3}

    def final_v(**more):
        res = M.run(scenario(models={**kw, **more}, t_end=2e-4))
        assert res.continuum.completed
        return res.continuum

    base = final_v()
    bm = final_v(integrator="blanes_moan4", dt_safety=1.45)
    ref = final_v(integrator="blanes_moan4", dt_safety=0.2).v[-1]
    assert bm.params["integrator"] == "blanes_moan4" and bm.params["dt_safety"] == 1.45
    assert bm.summary["dt"] > 2.5 * base.summary["dt"]
    err = {k: np.linalg.norm(r.v[-1] - ref) / np.linalg.norm(ref)
           for k, r in (("base", base), ("bm", bm))}
    assert err["bm"] < 1e-5 and err["bm"] < err["base"] / 10, err


def test_auto_picks_eq4_eq7_and_qc_by_the_strain_over_delta0():
    # the one rule of "auto" (ModelsSpec.continuum_model): Eq. 4 up to AUTO_EQ4_MAX_STRAIN
    # x δ0 (its quadratic Hertz force is 0.8 % off at 0.5 δ0, 7 % at 2 δ0), Eq. 7 above,
    # the quasi-continuum from AUTO_QC_MIN_STRAIN x δ0 and at δ0 = 0 (Eq. 7 is off by up
    # to 8-12 % there, qc within 2.2 %); an explicit model is kept whatever the amplitude
    from hertzchain.scenario import AUTO_EQ4_MAX_STRAIN, AUTO_QC_MIN_STRAIN

    assert (AUTO_EQ4_MAX_STRAIN, AUTO_QC_MIN_STRAIN) == (0.5, 9.0)
    sc = scenario(models={"continuum": "auto"})
    auto, chain = sc.models, sc.chain
    assert auto.continuum_model(chain, 0.09) == "eq4"
    assert auto.continuum_model(chain, AUTO_EQ4_MAX_STRAIN) == "eq4"
    assert auto.continuum_model(chain, None) == "eq4"  # not known (before the state)
    assert auto.continuum_model(chain, 0.51) == "eq7"
    assert auto.continuum_model(chain, 8.6) == "eq7"
    assert auto.continuum_model(chain, 8.99) == "eq7"
    assert auto.continuum_model(chain, AUTO_QC_MIN_STRAIN) == "qc"
    # a wave set at exactly 9 δ0 reads its peak back to round-off: still qc
    assert auto.continuum_model(chain, AUTO_QC_MIN_STRAIN * (1 - 1e-12)) == "qc"
    assert auto.continuum_model(chain, 100.0) == "qc"
    sonic = scenario(d0=0.0, models={"continuum": "auto"})
    assert sonic.models.continuum_model(sonic.chain, None) == "qc"
    assert sonic.models.continuum_model(sonic.chain, 0.09) == "qc"  # s ignored at δ0 = 0
    for name in ("eq4", "eq7", "qc"):
        given = scenario(models={"continuum": name})
        for s in (0.09, 8.6, 100.0):
            assert given.models.continuum_model(given.chain, s) == name
    doc = [k.doc for k in SCHEMA["models"] if k.name == "continuum"][0]
    assert "<= 0.5" in doc and ">= 9" in doc and "gravity; otherwise" in doc


@pytest.mark.parametrize(("chain", "why"), [
    ({"drag": 50.0}, r"\[chain\] drag = 50"),
    ({"law": "viscoelastic_hertz", "damping_time": 1e-7},
     r"\[chain\] law = 'viscoelastic_hertz' is dissipative"),
    ({"sections": [{"n": 40}, {"n": 60, "profile": "periodic",
                               "cell_diameters": [1.0, 0.8]}]},
     r"\[chain.sections\[1\]\] profile = 'periodic'"),
])
@pytest.mark.parametrize(("d0", "strain"), [(0.0, None), (1e-4, 9.0), (1e-5, 100.0)])
def test_auto_keeps_eq7_where_the_quasi_continuum_does_not_fit(chain, why, d0, strain):
    # qc is conservative and resolves grains: with drag, a dissipative law or periodic
    # cells "auto" runs Eq. 7 at δ0 = 0 and for strong waves; the reason is named
    from hertzchain.scenario import quasicontinuum_applies

    data = {"chain": {"delta0_over_d": d0, "sections": [{"n": 100}], **chain},
            "run": {"t_end": 1e-4}, "models": {"continuum": "auto"}}
    sc = parse_scenario(data)
    assert re.search(why, quasicontinuum_applies(sc.chain))
    assert sc.models.continuum_model(sc.chain, strain) == "eq7"
    lossless = parse_scenario({**data, "chain": {"delta0_over_d": d0,
                                                 "sections": [{"n": 100}]}})
    assert quasicontinuum_applies(lossless.chain) == ""
    assert lossless.models.continuum_model(lossless.chain, strain) == "qc"
    # a taper or gravity fits the quasi-continuum, but Eq. 7 was measured closer: Eq. 7
    graded = [{"delta0_over_d": d0, "sections": [
        {"n": 40}, {"n": 60, "profile": "tapered", "mass_ratio": 0.95}]}]
    if d0 == 0:  # gravity grades δ0 from 0: a sonic-vacuum chain only
        graded.append({"delta0_over_d": 0.0, "gravity": 9.81, "sections": [{"n": 100}]})
    for ch in graded:
        sc = parse_scenario({**data, "chain": ch})
        assert quasicontinuum_applies(sc.chain) == ""
        assert sc.models.continuum_model(sc.chain, strain) == "eq7"


@pytest.mark.parametrize("chain", [
    {}, {"drag": 50.0}, {"law": "viscoelastic_hertz", "damping_time": 1e-7},
    {"law": "power", "exponent": 2.0},
    {"delta0_over_d": 0.0, "gravity": 9.81, "top_force": 0.5},
    {"sections": [{"n": 40}, {"n": 60, "profile": "periodic", "cell_diameters": [1.0, 0.8]}]},
    {"sections": [{"n": 40}, {"n": 60, "profile": "tapered", "mass_ratio": 0.99}]},
    {"sections": [{"n": 40}, {"n": 60, "alpha_rho": 2.0, "alpha_kn": 0.5}]},
])
def test_quasicontinuum_applies_agrees_with_the_model_itself(chain):
    # the scenario-level reason (read off the scenario, without building the medium) is
    # the quasi-continuum's own refusal: GrainAveragedPDE raises ValueError exactly where
    # quasicontinuum_applies names a reason, on the medium the run builds
    import continuum
    from hertzchain.runner import build_chain, build_law
    from hertzchain.scenario import quasicontinuum_applies

    data = {"chain": {"delta0_over_d": 1e-4, "sections": [{"n": 100}], **chain},
            "run": {"t_end": 1e-4}}
    sc = parse_scenario(data)
    law, drag = build_law(sc.chain)
    medium = build_chain(sc.chain).medium(law, drag)
    why = quasicontinuum_applies(sc.chain)
    try:
        continuum.GrainAveragedPDE(medium, 3, bc="wall")
        refused = ""
    except ValueError as exc:
        refused = str(exc)
    assert bool(why) == bool(refused), (why, refused)


def test_the_run_resolves_auto_with_the_incident_amplitude():
    # the run resolves "auto" with the incident wave's amplitude: the paper's v̄max wave
    # (0.0822 m/s) is 0.09 δ0 at δ0/d = 1e-3 (Eq. 4) but several δ0 at 2e-4 (Eq. 7); the
    # sonic vacuum runs the quasi-continuum, with drag Eq. 7; the label names the model run
    from hertzchain.scenario import AUTO_EQ4_MAX_STRAIN

    kw = {"models": {"continuum": "auto", "samples": 3, "nodes_per_grain": 3}, "t_end": 3e-5}
    for d0, extra, model, name in ((1e-3, {}, "eq4", "Eq. 4"), (2e-4, {}, "eq7", "Eq. 7"),
                                   (0.0, {}, "qc", "quasi-continuum"),
                                   (0.0, {"drag": 50.0}, "eq7", "Eq. 7")):
        sc = scenario(d0=d0, **kw)
        if extra:
            sc = sc.with_values({f"chain.{k}": v for k, v in extra.items()})
        res = M.run(sc)
        s = res.summary()
        if d0 > 0:
            assert (s["incident_strain_over_delta0"] > AUTO_EQ4_MAX_STRAIN) \
                == (model == "eq7")
        assert s["continuum_model"] == model and res.continuum.completed, s
        assert res.continuum.label.startswith(f"continuum ({name},")


@pytest.mark.parametrize(("models", "extra", "match"), [
    ({"continuum": "eq4"}, {"d0": 0.0}, r"\[models\] continuum = 'eq4' needs a precompressed"),
    ({"continuum": "kdv"}, {"d0": 0.0}, r"\[models\] continuum = 'kdv' needs a precompressed"),
    ({"continuum": "kdv"}, {}, r"\[models\] continuum = 'kdv' is unidirectional"),
    ({"continuum": "eq5"}, {},
     r"\[models\] continuum = 'eq5'; did you mean 'eq7' or 'eq4'\? \(allowed: 'auto', "),
    ({"continuum": "auto", "nodes_per_grain": 4}, {}, r"nodes_per_grain = 4 must be odd"),
    ({"continuum": "auto", "nodes_per_grain": 0}, {}, r"nodes_per_grain = 0 must be >= 1"),
    ({"continuum": "auto", "order": 3}, {}, r"order = 3; allowed: 2, 4"),
    ({"continuum": "auto", "integrator": "rk4"}, {},
     r"\[models\] integrator = 'rk4' \(allowed: 'verlet'"),
    ({"continuum": "auto", "integrator": "blanes_moan4", "order": 2}, {},
     r"order = 2 contradicts integrator = 'blanes_moan4' \(order 4\)"),
    ({"continuum": "auto", "dt_safety": 0.8}, {},
     r"dt_safety = 0.8 is beyond the stability limit of integrator 'position_yoshida4': "
     r"allowed \(0, 0.7865\)"),
    ({"continuum": "auto", "integrator": "blanes_moan4", "dt_safety": 1.6}, {},
     r"dt_safety = 1.6 is beyond .* allowed \(0, 1.58"),
    ({"continuum": "auto", "dt_safety": 0.0}, {}, r"dt_safety = 0.0 is outside"),
    ({"continuum": "kdv", "dt_safety": 0.3}, {}, r"dt_safety do not apply to continuum = "
     r"\"kdv\""),
    ({"continuum": "kdv", "integrator": "verlet"}, {}, r"integrator, order and dt_safety do "
     r"not apply"),
    ({"continuum": "auto", "dispersion_cap": 11.0}, {}, r"dispersion_cap = 11.0 is outside"),
    ({"discrete": False, "theory": False}, {}, r"every model is off"),
    ({"samples": 1}, {}, r"samples = 1 must be >= 2"),
    ({"contiuum": "auto"}, {}, r"unknown key.*contiuum.*\[models\]"),
])
def test_models_errors_name_the_key(models, extra, match):
    with pytest.raises(ScenarioError, match=match):
        scenario(models=models, **extra)


@pytest.mark.parametrize(("initial", "run", "record", "match"), [
    ({"kind": "impact", "strain_max": 1e-4}, {}, {}, r"strain_max applies to kind"),
    ({"kind": "exact_wave", "center": 75}, {}, {}, r"exactly one of velocity_max .* strain_max"),
    ({"kind": "exact_wave", "center": 75, "velocity_max": 0.08, "strain_max": 1e-4}, {}, {},
     r"exactly one of"),
    ({}, {"dt": 1e-8, "dt_fraction": 0.01}, {}, r"\[run\] give dt or dt_fraction"),
    ({}, {"integrator": "rk4"}, {}, r"\[run\] integrator = 'rk4' \(allowed: 'verlet'"),
    ({}, {"dt_fraction": 2.0}, {}, r"dt_fraction = 2.0 is outside"),
    ({}, {}, {"snapshot_grains": [400]},
     r"snapshot_grains = \[400\]: 400 is not a grain; allowed range \[0, 399\]"),
    ({}, {}, {"series_every": 0}, r"series_every = 0 must be >= 1"),
    ({}, {}, {"energy_grid": 1}, r"energy_grid must be true or false"),
])
def test_new_keys_are_validated(initial, run, record, match):
    data = {"chain": {"delta0_over_d": 1e-3, "sections": [{"n": 150}, {"n": 250}]},
            "initial": initial or {"kind": "impact"}, "run": {"t_end": 1e-4, **run},
            "record": record}
    with pytest.raises(ScenarioError, match=match):
        parse_scenario(data)


def test_schema_is_documented_and_complete():
    text = schema_markdown()
    for table, keys in SCHEMA.items():
        for key in keys:
            assert f"\n{key.name} " in text, (table, key.name)
            assert key.doc, key.name
    import hertzchain.scenario as S

    ref = S.schema_reference()
    assert "[models]" in ref and "continuum = \"auto\"" in ref
    example = ref.split("::\n\n", 1)[1].split("\n\nKeys", 1)[0]
    import tomllib

    parsed = parse_scenario(tomllib.loads("\n".join(ln[4:] for ln in example.splitlines())))
    assert parsed.models.continuum == "auto"


def test_every_shipped_scenario_is_valid_and_round_trips():
    found = shipped_scenarios()
    assert {"table2_M", "mass_mismatch", "impact_sonic_vacuum"} <= set(found)
    for path in found.values():
        sc = load_scenario(path)
        assert sc.chain.n >= 2
        assert sc.with_values({}) == sc
        if not model_applies("continuum", sc.chain, sc.initial):  # "" where it applies
            assert sc.with_values({"models.continuum": "auto"}).models.continuum == "auto"
    with pytest.raises(ScenarioError, match="no entry 5"):
        sc.with_values({"chain.sections.5.n": 3})


# -- the run path -----------------------------------------------------------------------
def test_discrete_summary_is_the_runner_s():
    sc = scenario()
    res = M.run(sc, samples=True)
    direct = run_scenario(sc)
    assert res.discrete is not None and res.continuum is None
    for key, value in direct.items():
        if key != "wall_time":
            got = res.discrete.summary[key]
            assert got == value or (isinstance(value, float) and math.isnan(value)
                                    and math.isnan(got)), key
    # the samples: K times from 0 to t_end, the last one the final state
    assert res.discrete.times.size == sc.models.samples
    assert res.discrete.times[-1] == pytest.approx(sc.run.t_end)
    np.testing.assert_array_equal(res.discrete.v[-1], res.simulation.v)
    np.testing.assert_array_equal(res.discrete.v[0], res.initial.v)
    assert res.interfaces == [150]
    # without samples (no continuum): the plain scenario's run, initial and final states
    plain = M.run(sc)
    assert plain.discrete.times.size == 2 and plain.discrete.times[-1] == plain.simulation.t
    assert not plain.simulation.record.snapshots


@pytest.fixture(scope="module")
def with_continuum(tmp_path_factory):
    cache = tmp_path_factory.mktemp("cache")
    sc = scenario(models={"continuum": "auto", "nodes_per_grain": 3, "samples": 13})
    return sc, cache, M.run(sc, cache=cache, stem="shared")


def test_continuum_shares_the_initial_state_and_times(with_continuum):
    sc, _, res = with_continuum
    d, c = res.discrete, res.continuum
    assert c.completed and c.stopped_by == "t_end" and c.label.startswith("continuum (Eq. 4")
    np.testing.assert_array_equal(c.times, d.times)
    # same grain state at t = 0 (nodes sit on the grain centres)
    np.testing.assert_allclose(c.v[0], d.v[0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(c.strain[0, 1:-1], d.strain[0, 1:-1], rtol=0, atol=1e-18)
    # the exact discrete wave is a long wave here: the continuum follows it to a few %
    peak = np.max(np.abs(d.v[0]))
    assert np.max(np.abs(c.v[-1] - d.v[-1])) < 0.1 * peak
    assert c.summary["energy_drift"] < 1e-4


def test_cache_is_reused(with_continuum):
    sc, cache, first = with_continuum
    again = M.run(sc, cache=cache, stem="shared")
    assert again.discrete.cached and again.continuum.cached
    np.testing.assert_array_equal(again.continuum.v, first.continuum.v)
    np.testing.assert_array_equal(again.discrete.v, first.discrete.v)
    # another name and other [models] settings share the discrete run (same stem)
    other = dataclasses.replace(sc, name="renamed",
                                models=dataclasses.replace(sc.models, continuum=False))
    assert M.run(other, cache=cache, stem="shared", samples=True).discrete.cached


def test_out_file_of_other_continuum_settings_is_not_reused(tmp_path):
    """A continuum file named by ``out`` (no hash in its name) is reused only when every
    parameter of its key matches: the same times with another integrator/dt_safety are
    recomputed (before, a Yoshida-4 file came back as the Blanes–Moan run)."""
    kw = {"continuum": "eq4", "samples": 3, "nodes_per_grain": 3}
    out = tmp_path / "run.h5"
    first = M.run(scenario(models=kw, t_end=1e-4), out=out)
    assert first.continuum.completed and not first.continuum.cached
    same = M.run(scenario(models=kw, t_end=1e-4), out=out)
    assert same.continuum.cached  # (the check can pass: the file is reusable)
    other = M.run(scenario(models={**kw, "integrator": "blanes_moan4", "dt_safety": 1.45},
                           t_end=1e-4), out=out)
    assert not other.continuum.cached and other.continuum.params["integrator"] == "blanes_moan4"
    assert other.continuum.summary["dt"] > 2.5 * first.continuum.summary["dt"]


def test_until_front_at_samples_end_at_the_event(tmp_path):
    sc = parse_scenario({
        "chain": {"delta0_over_d": 1e-3, "sections": [{"n": 150}, {"n": 250, "alpha_kn": 2}]},
        "initial": {"kind": "exact_wave", "center": 75, "velocity_max": 0.0822},
        "run": {"until_front_at": 260}, "models": {"samples": 10}})
    res = M.run(sc, samples=True)
    d = res.discrete
    assert d.stopped_by == "until_front_at" and d.completed
    assert d.times[-1] == res.simulation.t
    # the theory's estimate of the stop time set the spacing: ~10 samples before it
    assert 7 <= d.times.size <= 14
    assert np.all(np.diff(d.times) > 0)


def test_failed_continuum_is_reported_not_compared(monkeypatch):
    import continuum

    def boom(*args, **kwargs):
        raise FloatingPointError("overflow in the stepper (test)")

    monkeypatch.setattr(continuum, "run", boom)
    res = M.run(scenario(models={"continuum": "eq4", "nodes_per_grain": 1, "samples": 4},
                         t_end=1e-4))
    c = res.continuum
    assert not c.completed and "overflow in the stepper" in c.stopped_by
    assert not res.completed
    assert res.summary()["continuum_completed"] is False
    # the comparison's summary (a sweep row) carries both models' completed / stopped_by
    from hertzchain.compare import analyse

    row = analyse(res).summary()
    assert row["completed"] is True and row["stopped_by"] == "t_end"
    assert row["continuum_completed"] is False
    assert "overflow in the stepper" in row["continuum_stopped_by"]
    assert "continuum_error" not in row  # not compared: no number


# -- the theory ---------------------------------------------------------------------------
def test_theory_reads_the_chain_and_is_mirrored_by_a_swap():
    ar, ak = theory.PAPER_POINTS["a"]
    res = M.run(scenario(ar, ak, models={"discrete": False}, n=(300, 250), center=150))
    th = res.theory
    assert th.alpha_rho == pytest.approx(ar) and th.alpha_kn == pytest.approx(ak, rel=1e-12)
    pred = theory.predict(ar, ak)
    assert th.gamma_rg == pytest.approx(pred.gamma_RG)
    # swap: the right section's material on the left, the left's on the right
    right = theory.PAPER_MATERIAL.scaled(ar, ak)
    swapped = parse_scenario({
        "chain": {"delta0_over_d": 1e-3 * ak ** (-2 / 3),
                  "material": {"density": right.density, "youngs_modulus": right.youngs_modulus,
                               "poisson_ratio": right.poisson_ratio},
                  "sections": [{"n": 300}, {"n": 250, "alpha_rho": 1 / ar,
                                            "alpha_kn": 1 / ak}]},
        "initial": {"kind": "exact_wave", "center": 150, "velocity_max": 0.0822},
        "run": {"t_end": 6e-4}, "models": {"discrete": False}})
    ts = M.run(swapped).theory
    assert ts.gamma_rg == pytest.approx(1 / th.gamma_rg, rel=1e-9)
    assert ts.gamma_c0 == pytest.approx(1 / th.gamma_c0, rel=1e-9)
    # the same energy transmission, the opposite sign of the reflected wave
    te = theory.energy_transmission(th.gamma_rg)
    assert theory.energy_transmission(ts.gamma_rg) == pytest.approx(te, rel=1e-12)
    assert ts.ratios["Ek_tr"] == pytest.approx(th.ratios["Ek_tr"], rel=1e-12)
    assert np.sign(ts.strain_re) == -np.sign(th.strain_re)
    mirror = {"I": "III", "II": "IV", "III": "I", "IV": "II"}
    assert ts.classes()["region"] == mirror[th.classes()["region"]]
    assert ts.classes()["transmitted"] != th.classes()["transmitted"]


def test_strain_from_velocity_solves_v_equals_V_xi_and_is_memoised():
    # v = V(ξ) ξ with Nesterenko's V (Eq. 1.4.28): the root to the bisection's 1e-13
    # relative width (so v to ~1e-12, V(ξ)ξ being smooth and increasing); a second call
    # for an equal side (a new dict) is the memo's, the same bits; no wave: NaN
    mat, d = theory.PAPER_MATERIAL, theory.PAPER_DIAMETER
    k, m = theory.hertz_constant(d, mat), theory.grain_mass(d, mat.density)
    for d0 in (1e-3 * d, 0.0):
        side = {"mass": m, "k": k, "delta0": d0, "d": d, "xi0": d0 / d,
                "c_mat": float(theory.c_mat(k, m, d)),
                "c0": float(theory.c0(k, m, d, d0)) if d0 > 0 else 0.0}
        xi = M.strain_from_velocity(side, 0.5)
        assert M._speed(side, xi) * xi == pytest.approx(0.5, rel=1e-11)
        hits = M._strain_from_velocity.cache_info().hits
        assert M.strain_from_velocity(dict(side), 0.5) == xi
        assert M._strain_from_velocity.cache_info().hits == hits + 1
    assert math.isnan(M.strain_from_velocity(side, 0.0))


# -- walls of a material ------------------------------------------------------------------
def _wall_scenario(left="free", right="brass", material="steel"):
    return parse_scenario({"chain": {"material": material, "left_wall": left,
                                     "right_wall": right, "sections": [{"n": 2}]},
                           "run": {"t_end": 1e-4}})


def test_wall_of_a_named_material_takes_both_materials():
    # k of a sphere on a flat of another material: (4/3) E* √(d/2), E* from both
    # (Johnson 1985, Eq. 4.22; theory.hertz_constant_wall), not the grain-grain k nor
    # the rigid flat's.
    from hertzchain.runner import build_chain

    steel, brass = theory.get_material("steel"), theory.get_material("brass")
    sc = _wall_scenario(left="flat", right="Brass")
    assert sc.chain.right_wall == "brass"  # the material's key
    ch = build_chain(sc.chain)
    d = float(ch.diameter[0])
    assert ch.k[-1] == pytest.approx(theory.hertz_constant_wall(d, steel, brass), rel=1e-14)
    assert ch.k[0] == pytest.approx(theory.hertz_constant_wall(d, steel, steel), rel=1e-14)
    assert ch.k[-1] < ch.k[0] < theory.hertz_constant_wall(d, steel)  # brass is softer
    assert ch.params["right_wall"]["flat"]["youngs_modulus"] == brass.youngs_modulus


@pytest.mark.parametrize("wall, match", [("bras", "did you mean 'brass'"),
                                         ("hertzz", "did you mean 'hertz'"),
                                         (3, "must be a string")])
def test_a_bad_wall_names_the_key_and_the_closest(wall, match):
    with pytest.raises(ScenarioError, match=r"\[chain\] right_wall") as err:
        _wall_scenario(right=wall)
    assert err.match(match)


def test_wall_force_and_impulse_are_the_two_body_collision():
    # One grain (m, at v toward the wall) meets a flat brass wall; its neighbour, at rest
    # behind it, separates at once (no overlap), so the wall contact is an isolated
    # two-body collision with m2 = ∞: peak force k_w (5 m v²/(4 k_w))^{3/5} (Johnson
    # 1985 §11.4; theory.tapers.wall_impact_force) and impulse 2 m v (an elastic
    # rebound).  Velocity Verlet at dt_fraction 0.002 puts the sampled peak within
    # (π·0.002·2)²-ish of the true one: tolerance 1e-4 (force), 1e-6 (impulse: the
    # trapezoid sum of a smooth pulse sampled every step).
    import discrete
    from hertzchain.runner import build_chain
    from theory.tapers import wall_impact_force

    ch = build_chain(_wall_scenario().chain)
    m, kw, v = float(ch.mass[1]), float(ch.k[-1]), 0.3
    init = discrete.initial.Initial(ch, np.zeros(2), np.array([0.0, v]))
    sim = init.simulation(record=discrete.Recording(wall_forces=True, series_every=1))
    t_c = 3.5 * (m ** 2 / (kw ** 2 * v)) ** 0.2  # > the collision time 3.2 (m²/k²v)^{1/5}
    sim.run(t_c, progress=False)
    t, f = np.asarray(sim.record.series_t), np.asarray(sim.record.wall_force)[..., 1].ravel()
    assert np.max(f) == pytest.approx(wall_impact_force(m, kw, v), rel=1e-4)
    assert np.trapezoid(f, t) == pytest.approx(2 * m * v, rel=1e-5)
