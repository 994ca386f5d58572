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
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np
import pytest

from hertzchain.cli import main
from hertzchain.scenario import ScenarioError, parse_scenario, schema_markdown
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
