"""Sweeps that lose their records, their workers or their memory.

* a lost ``records.jsonl``: the finished points are restored from ``results.h5``
  instead of the table being overwritten as all-pending;
* a worker loss (``KilledWorker``) leaves the point pending — a plain rerun retries it
  — instead of booking a permanent failure that only ``--retry-failed`` recovers;
* an axis or a product of axes beyond :data:`~hertzchain.sweep.spec.MAX_POINTS` is
  refused by name before anything is allocated (a dry run took 7 GB);
* a sweep whose points all fail exits non-zero; a bad byte in ``records.jsonl`` names
  the file and the line.
The point functions are small deterministic functions of the parameters, as in
``tests/hertzchain/test_sweep.py``.
"""

from __future__ import annotations

import logging
from types import SimpleNamespace

import numpy as np
import pytest

from hertzchain.sweep import (
    SUMMARY_FIELDS,
    RecordStore,
    SweepError,
    engine,
    parse_sweep_spec,
    read_results,
    run_sweep,
)
from hertzchain.sweep.cli import EXIT_ALL_FAILED, EXIT_PENDING, exit_status
from hertzchain.sweep.spec import MAX_POINTS

pytestmark = pytest.mark.timeout(300)


def spec_dict(axis=None):
    return {
        "name": "rel",
        "base": {"chain": {"sections": [{"n": 30}, {"n": 30}]}, "run": {"t_end": 1e-4}},
        "sweep": {"axes": [axis or {"path": "chain.sections.1.alpha_rho", "name": "ar",
                                    "values": [0.5, 1.0, 2.0]}]},
    }


CALLS: list[float] = []


def point_fn(scenario, *, out=None, progress=False):
    ar = scenario.chain.sections[1].alpha_rho
    CALLS.append(ar)
    summary = dict.fromkeys(SUMMARY_FIELDS, None)
    summary.update({"Ek_tr": 1 - ar / 10, "steps": 1000 + int(ar * 10),
                    "completed": ar < 1.5, "stopped_by": "t_end",
                    "transmitted": "fracture" if ar < 1 else "squeeze",
                    "energy_drift": 1e-9 * ar})
    return summary


def failing_fn(scenario, *, out=None, progress=False):
    raise FloatingPointError("always")


def _run(out, fn, client, **kw):
    return run_sweep(parse_sweep_spec(spec_dict()), out=out, point_function=fn,
                     client=client, progress=False, warmup=None, **kw)


def test_lost_records_are_restored_from_the_table(tmp_path, client):
    first = _run(tmp_path, point_fn, client)
    assert first.n_ok == 3
    before = read_results(tmp_path)
    (tmp_path / "records.jsonl").unlink()
    CALLS.clear()
    again = _run(tmp_path, point_fn, client)
    assert CALLS == [] and again.n_run == 0 and again.n_ok == 3  # nothing recomputed
    after = read_results(tmp_path)
    for name in ("id", "status", "Ek_tr", "steps", "completed", "transmitted", "ar"):
        x, y = before[name], after[name]
        assert list(x) == list(y) if x.dtype == object else np.array_equal(x, y), name
    restored = RecordStore(tmp_path / "records.jsonl").load()
    assert len(restored) == 3
    assert all(r["restored_from"].endswith("results.h5") for r in restored.values())
    assert {type(r["summary"]["completed"]) for r in restored.values()} == {bool}


def test_killed_worker_leaves_the_point_pending_and_a_rerun_retries(tmp_path, client,
                                                                    monkeypatch):
    from distributed import KilledWorker

    real = engine.run_point

    def dies_on_2(fn, scenario, point_id, values, target):
        if values["ar"] == 2.0:
            lost = SimpleNamespace(address="tcp://lost-worker")  # a WorkerState's field
            raise KilledWorker(f"hertzchain-point-{point_id}", lost, 3)
        return real(fn, scenario, point_id, values, target)

    monkeypatch.setattr(engine, "run_point", dies_on_2)
    out = _run(tmp_path, point_fn, client)
    assert (out.n_ok, out.n_failed, out.n_pending, out.n_lost) == (2, 0, 1, 1)
    assert exit_status(out) == EXIT_PENDING  # not success, not a permanent failure
    assert read_results(tmp_path)["status"].tolist().count("pending") == 1
    monkeypatch.setattr(engine, "run_point", real)
    again = _run(tmp_path, point_fn, client)  # no --retry-failed needed
    assert (again.n_run, again.n_ok, again.n_pending) == (1, 3, 0)


def test_old_killed_worker_failures_are_retried(tmp_path):
    spec = parse_sweep_spec(spec_dict())
    pts = spec.points()
    records = {p.id: {"id": p.id, "status": "failed", "error": "FloatingPointError: x"}
               for p in pts}
    records[pts[1].id]["error"] = "dask: KilledWorker: ('hertzchain-point-x', ...)"
    assert [p.id for p in engine.points_to_run(pts, records, None)] == [pts[1].id]


def test_every_point_failing_exits_non_zero(tmp_path, client):
    out = _run(tmp_path, failing_fn, client)
    assert out.n_failed == 3 and exit_status(out) == EXIT_ALL_FAILED


@pytest.mark.parametrize("axis", [
    {"path": "chain.sections.1.alpha_rho", "linspace": [0.5, 2.0, 10**9]},
    {"path": "chain.sections.1.alpha_rho", "logspace": [0.5, 2.0, MAX_POINTS + 1]},
])
def test_huge_axis_is_refused_before_allocating(axis):
    with pytest.raises(SweepError, match=r"count n = \d+ is beyond any sweep.*MAX_POINTS"):
        parse_sweep_spec(spec_dict(axis), validate_points=False)


def test_huge_product_is_refused_before_building_points():
    data = spec_dict()
    data["sweep"]["axes"] = [
        {"path": "chain.sections.1.alpha_rho", "linspace": [0.5, 2.0, 2000]},
        {"path": "chain.sections.1.alpha_kn", "linspace": [0.5, 2.0, 1000]}]
    with pytest.raises(SweepError, match="2000000 points .* allowed at most"):
        parse_sweep_spec(data)


def test_bad_byte_in_records_names_file_and_line(tmp_path, client):
    _run(tmp_path, point_fn, client)
    path = tmp_path / "records.jsonl"
    data = bytearray(path.read_bytes())
    second = data.index(b"\n") + 5
    data[second] = 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(ValueError, match=r"records\.jsonl line 2"):
        RecordStore(path).load()


@pytest.mark.slow
@pytest.mark.timeout(3600)
def test_shipped_amplitude_precompression_sweep_runs_clean(tmp_path):
    """Regression: 5 of its 12 points failed ("could not broadcast ... (60,) into
    (59,)", the settled wave clipped); every point must run and complete."""
    out = run_sweep("amplitude_precompression", out=tmp_path, workers=1, progress=False)
    assert (out.n_points, out.n_ok, out.n_failed, out.n_pending) == (12, 12, 0, 0)
    assert out.n_incomplete == 0
    res = read_results(tmp_path)
    assert set(res["error"]) == {""} and bool(np.all(res["completed"] == 1))


def slow_fn(scenario, *, out=None, progress=False):
    import time

    time.sleep(0.3)
    return point_fn(scenario)


def test_losing_every_worker_is_reported_not_a_silent_stall(tmp_path, monkeypatch):
    from distributed import Client, LocalCluster

    monkeypatch.setattr(engine, "NO_WORKER_GRACE", 1.0)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                      dashboard_address=":0", silence_logs=logging.ERROR) as cluster, \
            Client(cluster) as c:
        def lose_all(rec):
            cluster.scale(0)  # the only worker goes away after the first point

        with pytest.raises(SweepError, match="no worker for .* finished points are kept"):
            run_sweep(parse_sweep_spec(spec_dict()), out=tmp_path, point_function=slow_fn,
                      client=c, progress=False, warmup=None, on_result=lose_all)
    res = read_results(tmp_path)  # written on the way out
    assert res["status"].tolist().count("ok") >= 1
    assert res["status"].tolist().count("pending") >= 1
