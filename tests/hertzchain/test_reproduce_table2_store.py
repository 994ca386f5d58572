"""Table 2 / Fig. 8 keep a reduced file per point instead of the runner's energy grids.

The runner's file of a point (13–37 MB of float64 energy grids in ``--quick``) is reduced
once to ``table2-point-<hash>.h5``: the printed numbers in float64, Fig. 8's maps for
drawing in float16.  Checked here on point M: one small file is left, a second run
reuses it and gives exactly the same numbers, the maps are the full-precision ones to
float16's resolution (2^-11 relative), and Fig. 8's extremes come from the full grids.
"""

import json

import numpy as np
import pytest

from hertzchain.cache import canonical_json
from hertzchain.reproduce import fig8, table2
from hertzchain.reproduce.common import Context


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = tmp_path_factory.mktemp("t2")
    ctx1 = Context(out, progress=False, checkpoint_interval=None)
    first = table2.run(ctx1, points=("M",), continuum=False)[0]
    ctx2 = Context(out, progress=False, checkpoint_interval=None)
    again = table2.run(ctx2, points=("M",), continuum=False)[0]
    return out, ctx1, first, ctx2, again


def test_one_small_file_replaces_the_runner_file(runs):
    out, ctx1, first, ctx2, again = runs
    files = sorted((out / "runs").iterdir())
    assert [f.name.startswith("table2-point-") for f in files] == [True]
    assert files[0].stat().st_size < 1e6  # measured 0.17 MB (the runner's file: 13 MB)
    assert ctx1.computed == [files[0]] and ctx1.reused == []
    assert ctx2.computed == [] and ctx2.reused == [files[0]]


def test_reused_numbers_are_identical(runs):
    _, _, first, _, again = runs
    assert again.discrete == first.discrete
    assert again.drift == first.drift and len(first.drift) >= 3
    assert list(again.drift) == list(first.drift) == sorted(first.drift)  # report order
    assert list(again.discrete) == list(first.discrete)  # --json order
    assert again.incident == first.incident and again.theory == first.theory
    assert again.measured_at == first.measured_at
    assert canonical_json(again.summary) == canonical_json(json.loads(
        canonical_json(first.summary)))
    for key in ("refs", "max_right", "min_left", "limits", "stop", "interface"):
        assert again.maps[key] == first.maps[key], key
    np.testing.assert_array_equal(again.maps["t"], first.maps["t"])


def test_maps_for_drawing(runs):
    _, _, first, _, again = runs
    m = first.maps
    assert m["k"].shape == (m["t"].size, table2.GRAINS_SHOWN)
    assert m["t"].size <= table2.MAP_ROWS < m["stop"]
    # a run and a rerun draw the same maps: both float16-rounded (table2.MAP_DTYPE), the
    # total its own e_t/e_t0 (format 1 reread it as e_k/e_k0 + e_p/e_p0, up to 2x off)
    for key in ("k", "p", "t_"):
        assert m[key].dtype == again.maps[key].dtype == np.float32
        np.testing.assert_array_equal(again.maps[key], m[key])
    data = np.array([m["k"] * first.maps["refs"][0] + m["p"] * first.maps["refs"][1]])
    np.testing.assert_allclose(m["t_"] * first.maps["refs"][2], data[0], rtol=0,
                               atol=2.0**-9 * np.abs(data).max())
    # the extremes are those of the full grids, not of the drawn (decimated) maps
    assert m["max_right"]["k"] >= m["k"][:, m["interface"]:].max()
    data = fig8.run(Context(runs[0], progress=False), points=("M",))
    assert data["M"]["max_right"] == m["max_right"]
    assert data["M"]["gamma"] == (first.alpha_rho, first.alpha_kn)
