"""Jupyter display (``_repr_html_``) of the result objects: parsed back, values found.

Each object's HTML is parsed with :mod:`html.parser` into its tables (caption, rows of
cells as text); the tests check that every parameter and summary quantity appears with
its value and unit, that text is escaped (a scenario name with markup shows as text,
not as tags), and that a quantity outside its window is absent, not "nan".
"""

from __future__ import annotations

import math
from html.parser import HTMLParser

import numpy as np
import pytest

import discrete
from discrete.display import html_table, html_value
from hertzchain.scenario import parse_scenario


class _Tables(HTMLParser):
    """Tables of an HTML fragment: [(caption, [[cell text, ...], ...])], and the tags."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tables: list[tuple[str, list[list[str]]]] = []
        self.tags: list[str] = []
        self._text: list[str] | None = None
        self._row: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        if tag == "table":
            self.tables.append(("", []))
        elif tag == "tr":
            self._row = []
        elif tag in ("td", "th", "caption"):
            self._text = []

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._row is not None:
            self._row.append("".join(self._text))
        elif tag == "caption":
            self.tables[-1] = ("".join(self._text), self.tables[-1][1])
        elif tag == "tr":
            self.tables[-1][1].append(self._row)
            self._row = None
        if tag in ("td", "th", "caption"):
            self._text = None

    def handle_data(self, data):
        if self._text is not None:
            self._text.append(data)


def parse(text: str) -> _Tables:
    p = _Tables()
    p.feed(text)
    p.close()
    return p


def rows_of(text: str) -> dict[str, list[str]]:
    """{first cell: the row's other cells} over every table body row."""
    out = {}
    for _, rows in parse(text).tables:
        for r in rows[1:]:
            out[r[0]] = r[1:]
    return out


def test_html_table_escapes_text_and_writes_numbers():
    text = html_table("<script>alert(1)</script>", [("a & b", "<i>x</i>", "m/s"),
                                                     ("n", 3, "1"), ("x", math.nan, "s"),
                                                     ("v", [1.0, 2.5], "m/s")])
    p = parse(text)
    assert "script" not in p.tags and "i" not in p.tags
    caption, rows = p.tables[0]
    assert caption == "<script>alert(1)</script>"  # shown as text
    assert rows[1] == ["a & b", "<i>x</i>", "m/s"]
    assert rows[2] == ["n", "3", "1"] and rows[3] == ["x", "n/a", "s"]
    assert rows[4] == ["v", "1, 2.5", "m/s"]
    assert html_value(True) == "true" and html_value(1.23456789e-7) == "1.23457e-07"


@pytest.fixture(scope="module")
def placed():
    sc = parse_scenario({"name": "<b>wave</b> & co", "chain": {"sections": [{"n": 120}]},
                         "initial": {"kind": "exact_wave", "center": 30,
                                     "velocity_max": 0.1},
                         "run": {"until_front_at": 80}})
    from hertzchain.models import run

    return run(sc)


def test_simulation_and_run_info_display_their_parameters_and_state(placed):
    sim = placed.simulation
    rows = rows_of(sim._repr_html_())
    assert rows["grains"] == ["120", "1"]
    assert rows["dt"] == [f"{sim.dt:.6g}", "s"]
    assert rows["t"] == [f"{sim.t:.6g}", "s"]
    assert rows["steps"] == [str(sim.steps), "1"]
    assert float(rows["energy E"][0]) == pytest.approx(sim.energy(), rel=1e-5)
    assert rows["energy E"][1] == "J"
    assert float(rows["largest |v|"][0]) == pytest.approx(np.max(np.abs(sim.v)), rel=1e-5)
    info = discrete.RunInfo(12, 1e-6, "t_end", 1e-9, 2e-10)
    rows = rows_of(info._repr_html_())
    assert rows["steps"] == ["12", "1"] and rows["stopped by"] == ["t_end", ""]
    assert rows["energy drift"] == ["1e-09", "1"]


def test_a_run_displays_its_parameters_summary_and_train(placed):
    from hertzchain.measure import SUMMARY_UNITS

    text = placed._repr_html_()
    p = parse(text)
    assert "b" not in p.tags  # the name's markup is text
    captions = [c for c, _ in p.tables]
    assert captions[0] == "<b>wave</b> & co: parameters"
    rows = rows_of(text)
    assert rows["name"] == ["<b>wave</b> & co", ""]
    assert rows["initial.velocity_max"] == ["0.1", "m/s"]
    assert rows["chain.sections.0.n"][0] == "120"
    summary = placed.summary()
    for key in ("t", "dt", "steps", "energy_drift", "front_speed_tr", "incident_strain"):
        assert rows[key] == [f"{summary[key]:.6g}" if isinstance(summary[key], float)
                             else str(summary[key]), SUMMARY_UNITS[key]], key
    # outside its window: absent (one section, no energy ratios), its note shown
    assert "Et_tr" not in rows and "nan" not in text.lower()
    assert rows["ratios_note"][0] == "one section: no interface"
    # the train: one wave, its numbers
    assert rows["train_waves"][0] == "1"
    assert f"v_max (m/s) {summary['train_velocity_max'][0]:.5g}" in rows["train wave 1"][0]


def test_a_comparison_displays_its_verdict_and_differences(placed):
    from hertzchain.compare import analyse
    from hertzchain.compare_output import difference_rows

    cmp = analyse(placed)
    text = cmp._repr_html_()
    p = parse(text)
    assert "b" not in p.tags
    captions = [c for c, _ in p.tables]
    assert any("differences to the discrete chain" in c for c in captions)
    rows = rows_of(text)
    for row in difference_rows(cmp):
        assert rows[row[0]] == row[1:]
    assert cmp.verdict() in text.replace("&#x27;", "'").replace("&amp;", "&")
    assert rows["train_waves"][0] == "1"
