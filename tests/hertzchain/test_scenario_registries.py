r"""A contact law registered in this file alone is a scenario law, with its own parameter.

:class:`IndexPowerLaw` is what a user writes in a new file of ``theory/laws/``: the
power law :math:`F = k[\delta]_+^{p}` (N; Nesterenko 2001, *Dynamics of Heterogeneous
Materials*, §1.1) whose exponent is its own parameter ``power_index`` (a
:class:`theory.laws.LawParameter`: range [2, 4], default 3), and one
:func:`theory.laws.register_law` call.  Nothing of :mod:`hertzchain` is edited, and

* a scenario TOML names it (``[chain] law = "index_power_test"``, ``power_index``),
  and ``hertzchain run`` runs it: with p = 2 it reproduces the built-in power law of
  exponent 2 (an independent implementation: ``k * r ** p`` here, ``k * (r * r)`` in
  :class:`theory.laws.PowerLaw`), and p = 2.5 gives a different wave (so the parameter
  reaches the solver);
* a bad value is refused naming the key and its range, a misspelt key or law name gets
  a did-you-mean, and the parameter of another law is refused naming its law;
* the scenario reference (:func:`hertzchain.scenario.schema_markdown`) lists the key
  while the law is registered, and not after.

Likewise :class:`StruckGrain`, an initial kind (:class:`hertzchain.initial_kinds.InitialKind`:
one grain struck anywhere) registered here alone, is a value of ``[initial] kind`` with
its own key, validated and documented, and runs through ``hertzchain run``: struck at
grain 0 it is the impact, number for number, and struck at grain 5 its wave is the
impact's shifted by 5 grains.
"""

from __future__ import annotations

import json
import math
import re
from typing import Any

import numpy as np
import pytest

from hertzchain.cli import main
from hertzchain.initial_kinds import (
    IMPACT_FORMATION,
    INITIAL_KINDS,
    V0,
    InitialKind,
    register_initial_kind,
)
from hertzchain.scenario import Key, ScenarioError, parse_scenario, schema_markdown
from theory.laws import LAWS, ContactLaw, LawParameter, compile_piece, register_law


class IndexPowerLaw(ContactLaw):
    r"""Power law :math:`F = k[\delta]_+^{p}` (N) with its exponent as a parameter."""

    name = "index_power_test"
    dissipative = False
    summary = "F = k δ^p (p = power_index; registered by a test)"
    parameters = (LawParameter("power_index", 3.0, "the exponent p", low=2.0,
                               low_open=False, high=4.0, high_open=False),)

    def __init__(self, power_index: float = 3.0) -> None:
        self.exponent = float(power_index)

    def key(self) -> tuple:
        """The compiled force depends on p."""
        return (self.name, self.exponent)

    def to_dict(self) -> dict[str, Any]:
        """JSON-able description."""
        return {"law": self.name, "power_index": self.exponent}

    def describe(self) -> str:
        """One line."""
        return f"k [delta]_+^{self.exponent:g} (test law)"

    def make_force(self):
        """Compiled F = k [r]_+^p, N (``**``: not the built-in law's products)."""
        n = self.exponent

        def force(r, rd, k, p):
            return k * max(r, 0.0) ** n

        return compile_piece(force)

    def force(self, r, rd, k):
        """NumPy twin of :meth:`make_force`, N."""
        return np.asarray(k, float) * np.maximum(np.asarray(r, float), 0.0) ** self.exponent


@pytest.fixture
def law():
    """The law, registered for one test (removed from LAWS afterwards)."""
    register_law(IndexPowerLaw)
    try:
        yield IndexPowerLaw
    finally:
        LAWS.pop(IndexPowerLaw.name, None)


TOML = """name = "{name}"
[chain]
law = "{law}"
{params}
[[chain.sections]]
n = 60
[initial]
kind = "impact"
v0 = 1.0
[run]
until_front_at = 40
"""


def _run(tmp_path, law: str, params: str) -> dict:
    path = tmp_path / f"{law}-{abs(hash(params))}.toml"
    path.write_text(TOML.format(name=path.stem, law=law, params=params))
    return path


def _summary(tmp_path, capsys, law: str, params: str) -> dict:
    path = _run(tmp_path, law, params)
    assert main(["run", str(path), "--json", "--no-progress"]) == 0
    return json.loads(capsys.readouterr().out)


def test_registered_law_runs_from_a_scenario_file(law, tmp_path, capsys):
    mine = _summary(tmp_path, capsys, "index_power_test", "power_index = 2.0")
    ref = _summary(tmp_path, capsys, "power", "exponent = 2.0")
    other = _summary(tmp_path, capsys, "index_power_test", "power_index = 2.5")
    d_mine, d_ref = mine, ref
    assert d_mine["completed"] and d_ref["completed"]
    compared = 0
    for key, value in d_ref.items():
        if isinstance(value, float) and math.isfinite(value) and "wall_time" not in key:
            # two roundings of k r^2 over a few thousand steps: 1e-9 relative
            assert d_mine[key] == pytest.approx(value, rel=1e-9, abs=1e-300), key
            compared += 1
    assert compared >= 5
    speed = "front_speed_tr"
    assert speed in d_ref and d_ref[speed] > 0
    # p = 2.5 is another wave: its front speed differs by far more than the tolerance
    assert abs(other[speed] / d_ref[speed] - 1) > 1e-2


def test_registered_law_parameter_is_validated(law):
    chain = {"law": "index_power_test", "sections": [{"n": 10}]}
    run = {"t_end": 1e-4}
    sc = parse_scenario({"chain": {**chain, "power_index": 2.5}, "run": run})
    assert sc.chain.law_values == {"power_index": 2.5}
    assert sc.chain.contact_law() == IndexPowerLaw(2.5) and sc.chain.exponent == 2.5
    assert sc.to_dict()["chain"]["power_index"] == 2.5
    assert sc.with_values({"chain.power_index": 3.5}).chain.exponent == 3.5
    bad = [({"power_index": 5.0}, r"\[chain\] power_index = 5.0 is outside the allowed "
                                  r"range \[2, 4\]"),
           ({"power_indx": 2.0}, r"unknown key 'power_indx' in \[chain\]; did you mean "
                                 r"'power_index'\?"),
           ({"law": "index_power_tst"}, r"law = 'index_power_tst'; did you mean "
                                        r"'index_power_test'\?"),
           ({"law": "power", "power_index": 2.5},
            r"power_index = 2.5 applies to law = 'index_power_test' only \(law = 'power'"),
           ({"exponent": 2.0}, r"exponent = 2.0 applies to law = 'power' only")]
    for extra, message in bad:
        with pytest.raises(ScenarioError, match=message):
            parse_scenario({"chain": {**chain, **extra}, "run": run})


def test_registered_law_is_in_the_scenario_reference(law):
    text = schema_markdown()
    line = next(ln for ln in text.splitlines() if ln.startswith("power_index "))
    assert "law = \"index_power_test\": the exponent p" in line and "[2, 4]" in line
    assert "\"index_power_test\" F = k δ^p" in text
    LAWS.pop(IndexPowerLaw.name)
    assert "power_index" not in schema_markdown()


# --------------------------------------------------------------- an initial kind
class StruckGrain(InitialKind):
    """Grain ``struck_grain`` moves at ``v0``, the rest at rest (an impact anywhere)."""

    name = "struck_grain_test"
    doc = "grain struck_grain at v0 (registered by a test)"
    keys = (V0, Key("struck_grain", "integer", 0, "the grain struck", low=0,
                    low_open=False))
    interpolation = "grains"
    single_struck_grain = True

    def check(self, spec, chain):
        """The struck grain lies in the first half of the chain."""
        if not spec.struck_grain < chain.n // 2:
            raise ScenarioError(f"[initial] struck_grain = {spec.struck_grain}: allowed "
                                f"range [0, {chain.n // 2 - 1}] (the first half)")

    def amplitude_key(self, spec):
        """``v0``."""
        return "v0"

    def build(self, spec, chain_spec, chain, *, cache_dir=None):
        """One grain at v0."""
        from discrete.initial import Initial

        v = np.zeros(chain.n)
        v[spec.struck_grain] = spec.v0
        return Initial(chain, np.zeros(chain.n), v,
                       params={"kind": self.name, "v0": spec.v0, "grain": spec.struck_grain})

    def incident_velocity(self, init):
        """The impact's estimate (the wave forms on the way)."""
        return IMPACT_FORMATION * float(np.max(np.abs(init.v)))


@pytest.fixture
def kind():
    """The kind, registered for one test (removed afterwards)."""
    register_initial_kind(StruckGrain())
    try:
        yield StruckGrain
    finally:
        INITIAL_KINDS.pop(StruckGrain.name, None)


KIND_TOML = """name = "{name}"
[chain]
[[chain.sections]]
n = {n}
[initial]
kind = "{kind}"
v0 = 1.0
{extra}
[run]
until_front_at = {until}
"""


def _run_kind(tmp_path, capsys, name, n, kind, extra, until) -> dict:
    path = tmp_path / f"{name}.toml"
    path.write_text(KIND_TOML.format(name=name, n=n, kind=kind, extra=extra, until=until))
    assert main(["run", str(path), "--json", "--no-progress"]) == 0
    return json.loads(capsys.readouterr().out)


def test_registered_kind_runs_through_hertzchain_run(kind, tmp_path, capsys):
    # struck_grain = 0 is the impact: the same run, number for number (one code path)
    ref = _run_kind(tmp_path, capsys, "impact", 60, "impact", "", 40)
    same = _run_kind(tmp_path, capsys, "grain0", 60, "struck_grain_test",
                     "struck_grain = 0", 40)
    assert ref["completed"] and same["completed"]
    for key, value in ref.items():
        if "wall_time" not in key:
            assert same[key] == value or (value != value and same[key] != same[key]), key
    # grain 5 struck in a 65-grain chain: grains 0-4 stay at rest (δ0 = 0, the struck
    # grain moves away from them), so the wave is the impact's shifted by 5 grains and
    # reaches grain 45 after the same steps and time (the same arithmetic per grain)
    shifted = _run_kind(tmp_path, capsys, "grain5", 65, "struck_grain_test",
                        "struck_grain = 5", 45)
    assert shifted["steps"] == ref["steps"]
    assert shifted["t"] == pytest.approx(ref["t"], rel=1e-12, abs=0)


def test_registered_kind_is_validated_and_documented(kind):
    chain = {"sections": [{"n": 20}]}
    run = {"t_end": 1e-4}
    sc = parse_scenario({"chain": chain, "initial": {"kind": "struck_grain_test",
                                                     "struck_grain": 3}, "run": run})
    assert sc.initial.struck_grain == 3 and sc.initial.initial_kind.name == kind.name
    assert sc.to_dict()["initial"]["struck_grain"] == 3
    assert sc.initial.center is None  # another kind's key: its default
    bad = [({"kind": "struck_grain_tset"}, r"did you mean 'struck_grain_test'\?"),
           ({"kind": "struck_grain_test", "struck_grain": 10},
            r"struck_grain = 10: allowed range \[0, 9\]"),
           ({"kind": "struck_grain_test", "struck_grain": -1},
            r"struck_grain = -1 must be >= 0"),
           ({"kind": "struck_grain_test", "struck_grian": 1},
            r"unknown key 'struck_grian' in \[initial\]; did you mean 'struck_grain'\?"),
           ({"kind": "impact", "struck_grain": 2},
            r"struck_grain applies to kind = 'struck_grain_test' only \(kind = 'impact'\)"),
           ({"kind": "struck_grain_test", "center": 5},
            r"center applies to kind = 'cut_wave' or 'exact_wave' only")]
    for initial, message in bad:
        with pytest.raises(ScenarioError, match=message):
            parse_scenario({"chain": chain, "initial": initial, "run": run})
    text = schema_markdown()
    assert "struck_grain_test" in text and "struck_grain_test: the grain struck" in text
    assert "impact, cut_wave, struck_grain_test: impact velocity" in text


def test_no_kind_name_is_compared_outside_the_registry():
    # the modules that use the initial state ask its kind, never its name
    import re
    from pathlib import Path

    root = Path(__file__).resolve().parents[2] / "hertzchain"
    names = r"""["'](impact|cut_wave|exact_wave)["']"""
    patterns = [re.compile(r"(==|!=|\bin)\s*\(?\s*" + names),  # kind == "impact", in (...)
                re.compile(names + r"\s*(:|==|!=)"),  # {"impact": ...} dispatch
                re.compile(r"\b(initial|ini)\.kind\s*(==|!=|\bin\b)")]  # any comparison
    for name in ("scenario.py", "runner.py", "models.py", "compare.py"):
        text = (root / name).read_text()
        for pattern in patterns:
            assert not pattern.search(text), (name, pattern.search(text))


# --------------------------------------------------------------- continuum models
def test_continuum_choices_and_label_come_from_the_registry():
    import continuum
    from hertzchain.models import continuum_label
    from hertzchain.scenario import continuum_models

    base = {"chain": {"delta0_over_d": 1e-3, "sections": [{"n": 20}]},
            "run": {"t_end": 1e-4}}
    assert continuum_models() == ("auto", *continuum.MODELS, "kdv")
    with pytest.raises(ScenarioError, match=r"continuum = 'eq5'; did you mean .*'eq4'"):
        parse_scenario({**base, "models": {"continuum": "eq5"}})

    class Eq7Copy(continuum.NesterenkoPDE):
        """Eq. 7 under another name (a model registered by a test)."""

        name = "eq7_copy_test"
        label = "Eq. 7 (copy)"

    continuum.register_model(Eq7Copy)
    try:
        sc = parse_scenario({**base, "models": {"continuum": "eq7_copy_test"}})
        assert sc.models.continuum_model(sc.chain) == "eq7_copy_test"
        assert continuum_label("eq7_copy_test", sc.models).startswith(
            "continuum (Eq. 7 (copy), 5 nodes/grain")
        assert "'eq7_copy_test'" in schema_markdown()
    finally:
        continuum.MODELS.pop(Eq7Copy.name, None)
    assert continuum_label("eq4", sc.models) == "continuum (Eq. 4, 5 nodes/grain)"
    allowed = ", ".join(repr(m) for m in continuum_models())
    with pytest.raises(ScenarioError, match=re.escape(f"allowed: {allowed} or false")):
        parse_scenario({**base, "models": {"continuum": "eq7_copy_test"}})


def test_nonlinearity_full_and_its_hertz_alias():
    base = {"chain": {"delta0_over_d": 1e-3, "sections": [{"n": 20}]},
            "run": {"t_end": 1e-4}}
    for value in ("quadratic", "full", "hertz"):
        assert parse_scenario({**base, "models": {"nonlinearity": value}}) \
            .models.nonlinearity == value
    cones = {**base, "chain": {**base["chain"], "exponent": 2.0}}
    assert parse_scenario({**cones, "models": {"nonlinearity": "full"}}).chain.exponent == 2
    with pytest.raises(ScenarioError, match=r"nonlinearity = 'hertz' is the Hertz law's "
                                            r"full force.*exponent 2: use 'full'"):
        parse_scenario({**cones, "models": {"nonlinearity": "hertz"}})
