"""Integration: a tiny real sweep (the runner and the discrete solver) on a Dask worker.

One worker process: its warm-up computes the settled wave that tiny.toml cuts (~4 s of
CPU per process), which two workers would each pay on this shared 2-core machine; the
multi-worker machinery is tested with synthetic points in test_sweep.py.
"""

from importlib.resources import files

import numpy as np
import pytest

pytest.importorskip("hertzchain.runner", reason="hertzchain.runner is not available yet")

from hertzchain.sweep import (  # noqa: E402 - after the skip
    SUMMARY_FIELDS,
    classification_agreement,
    load_sweep_spec,
    read_results,
    run_sweep,
)
from hertzchain.sweep_plot import save_sweep_figures  # noqa: E402

pytestmark = pytest.mark.timeout(300)


@pytest.fixture(scope="module")
def tiny_results(tmp_path_factory):
    out = tmp_path_factory.mktemp("tiny-sweep")
    spec = load_sweep_spec(files("hertzchain") / "sweeps" / "tiny.toml")
    outcome = run_sweep(spec, out=out, workers=1, progress=False)
    return outcome, read_results(outcome.table)


def test_tiny_real_sweep(tiny_results):
    outcome, res = tiny_results
    assert outcome.n_points == 4 and outcome.n_pending == 0
    assert outcome.n_ok == 4, list(res["error"])
    for key in SUMMARY_FIELDS:
        assert key in res, key
    assert set(res["transmitted"]) <= {"fracture", "squeeze", "none"}
    assert set(res["reflected"]) <= {"compressive", "expansive", "none"}
    for key in ("Ek_tr", "Ek_re", "Et_tr", "Et_re"):
        assert np.all(np.isfinite(res[key])), key
    assert np.all(res["steps"] > 0) and np.all(res["dt"] > 0)
    assert np.all(np.abs(res["energy_drift"]) < 1e-3)


def test_tiny_real_sweep_is_resumable_and_plots(tiny_results, tmp_path):
    outcome, res = tiny_results
    again = run_sweep(load_sweep_spec(files("hertzchain") / "sweeps" / "tiny.toml"),
                      out=outcome.directory, workers=1, progress=False)
    assert again.n_run == 0 and again.n_skipped == 4
    written = save_sweep_figures(res, tmp_path / "map.png")
    assert all(p.exists() for p in written)
    agreement = classification_agreement(res)
    assert agreement.n_classified == 4
