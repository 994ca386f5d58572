"""``hertzchain compare`` runs on every shipped scenario.

Each scenario of ``hertzchain/scenarios/**`` (paper, examples and the top-level ones)
is compared with its own chain, initial state and models, cut to a short run (30 µs,
~600 discrete steps) so that the whole set stays cheap: what is checked is that every
model of every scenario runs from the same grains through the one run path and that the
comparison, its files and its report are written — not the accuracy (the accuracy tests
are ``test_compare_accuracy.py``; the full-length runs are ``hertzchain reproduce``).
"""

import math
import tomllib

import pytest

from hertzchain.compare import compare, read_comparison
from hertzchain.scenario import parse_scenario, shipped_scenarios

T_SHORT = 3e-5
"""s: long enough for every model to take many steps, short for the suite."""

SHIPPED = shipped_scenarios()


def short(path) -> dict:
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    run = dict(data.get("run") or {})
    run.pop("until_front_at", None)
    run["t_end"] = min(float(run.get("t_end") or T_SHORT), T_SHORT)
    data["run"] = run
    # snapshots requested later than the short run (wave positions, times) would make
    # it incomplete, rightly: they are left out
    record = dict(data.get("record") or {})
    record.pop("snapshot_grains", None)
    record["snapshot_times"] = [t for t in record.get("snapshot_times", []) if t <= T_SHORT]
    data["record"] = record
    return data


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("shipped-runs")


def test_every_shipped_scenario_is_found():
    assert len(SHIPPED) >= 20
    assert {"table2_M", "mass_mismatch", "impact_sonic_vacuum"} <= set(SHIPPED)


# the examples with their own contact law or disorder compile their own kernels
# (~20 s each): slow
EXPENSIVE = {"law_drag", "law_linear", "law_power_cones", "law_viscoelastic_hertz",
             "chain_disorder", "fig5"}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n in EXPENSIVE
                                  else n for n in sorted(SHIPPED)])
def test_compare_runs_on_shipped_scenario(name, cache, tmp_path):
    sc = parse_scenario(short(SHIPPED[name]))
    cmp = compare(sc, cache=cache, out=tmp_path / "cmp")
    assert cmp.run.discrete is not None and cmp.run.discrete.completed
    if sc.models.continuum:
        c = cmp.run.continuum
        assert c is not None
        # a continuum either completes or says why it stopped — never silently
        assert c.completed or c.stopped_by
    assert math.isclose(cmp.run.discrete.times[-1], T_SHORT, rel_tol=0.01) \
        or cmp.run.discrete.times[-1] <= T_SHORT
    assert cmp.verdict().endswith(".")
    stored = read_comparison(tmp_path / "cmp" / "compare.h5")
    assert stored["summary"]["verdict"] == cmp.verdict()
