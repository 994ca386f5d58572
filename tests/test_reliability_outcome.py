"""Every run says how it ended; labels only where they mean something.

Before: a run cut short by ``max_steps`` (before ``t_end`` or ``until_front_at``), a run
of no step, ``dt = 1e-300`` or a snapshot never taken all exited 0 with a full
summary, and the transmitted/reflected labels were computed on the final state even
when the wave had not reached the interface (a uniform chain, where nothing can
reflect, was called "expansive").  Now:

* impossible stops are refused before the run (:func:`hertzchain.runner.check_stop`:
  ``ScenarioError`` naming the key, exit 2, no file);
* a run that ends before the stop it asked for (only knowable at the end:
  ``until_front_at``, a snapshot at a time the run never reached) is summarised with
  ``completed = false``, ``stopped_by`` and ``incomplete_reason``, written, and the CLI
  exits 3 with a message; sweeps record the same columns and count such points;
* ``transmitted``, ``reflected`` and ``n_transmitted_pulses`` are None ("" in sweep
  tables) unless the waves separated; "none" is a measured answer.

The runs are exact solitary waves on short precompressed chains (< 1 s each).
"""

from __future__ import annotations

import json
import logging

import h5py
import numpy as np
import pytest

from hertzchain import checkpoint as C
from hertzchain.cli import EXIT_INCOMPLETE, main
from hertzchain.files import describe
from hertzchain.runner import build_simulation, run_scenario
from hertzchain.scenario import ScenarioError, parse_scenario


def _wave(ar: float = 0.5, ak: float = 2.0, **run) -> dict:
    """Exact wave at grain 75 of 150 | 200 grains (δ0/d = 1e-3); reaches the interface
    at t ≈ 0.45 ms, the waves have separated by 0.75 ms."""
    return {"name": "w", "chain": {"delta0_over_d": 1e-3, "sections": [
        {"n": 150}, {"n": 200, "alpha_rho": ar, "alpha_kn": ak}]},
        "initial": {"kind": "exact_wave", "center": 75, "velocity_max": 0.0822},
        "run": run or {"t_end": 7.5e-4}}


def _toml(d: dict, path) -> str:
    lines = [f'name = "{d["name"]}"', "[chain]"]
    for k, v in d["chain"].items():
        if k != "sections":
            lines.append(f"{k} = {json.dumps(v)}")
    for sec in d["chain"]["sections"]:
        lines += ["[[chain.sections]]"] + [f"{k} = {json.dumps(v)}" for k, v in sec.items()]
    for table in ("initial", "run", "record"):
        lines.append(f"[{table}]")
        lines += [f"{k} = {json.dumps(v)}" for k, v in d.get(table, {}).items()]
    path.write_text("\n".join(lines) + "\n")
    return str(path)


# -- refused before the run ------------------------------------------------------------
@pytest.mark.parametrize(("run", "match"), [
    # max_steps ends the run before t_end (it used to stop there and exit 0)
    ({"t_end": 7.5e-4, "max_steps": 10}, r"\[run\] max_steps = 10 ends the run at t = "
                                         r"[0-9.e-]+ s, before t_end = 0.00075 s"),
    # 1e297 steps: refused, not run for days (or until max_steps)
    ({"t_end": 7.5e-4, "dt": 1e-300}, r"max_steps = 100000000 .* needs 7.5e\+296 steps"),
    # no step at all: t_end below one step
    ({"t_end": 1e-18, "dt": 1e-8}, r"\[run\] t_end = 1e-18 s is shorter than one time step"),
    # t_end = 1e300 with max_steps = 10 (was a TypeError from the energy-grid coarsening)
    ({"t_end": 1e300, "max_steps": 10}, r"\[run\] max_steps = 10 ends the run"),
])
def test_unreachable_stop_is_refused_up_front(run, match):
    with pytest.raises(ScenarioError, match=match):
        run_scenario(parse_scenario(_wave(**run)))


def test_snapshot_beyond_max_steps_is_refused():
    d = {**_wave(until_front_at=300, max_steps=1000), "record": {"snapshot_times": [1e-3]}}
    with pytest.raises(ScenarioError, match=r"\[record\] snapshot_times = \[0.001\]: 0.001 s "
                                            r"comes after max_steps = 1000 steps"):
        run_scenario(parse_scenario(d))


def test_refused_through_cli_writes_nothing(tmp_path, capsys):
    out = tmp_path / "r.h5"
    toml = _toml(_wave(t_end=7.5e-4, max_steps=10), tmp_path / "s.toml")
    assert main(["run", toml, "--out", str(out)]) == 2
    assert "error: [run] max_steps = 10 ends the run" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == [tmp_path / "s.toml"]


# -- ran, but not to the requested stop ---------------------------------------------------
def test_until_front_at_cut_by_max_steps_exits_3(tmp_path, capsys):
    out = tmp_path / "r.h5"
    toml = _toml(_wave(until_front_at=300, max_steps=2000), tmp_path / "s.toml")
    assert main(["run", toml, "--out", str(out), "--json"]) == EXIT_INCOMPLETE
    cap = capsys.readouterr()
    summary = json.loads(cap.out)
    assert summary["completed"] is False and summary["stopped_by"] == "max_steps"
    assert summary["steps"] == 2000
    assert "before the wave front reached grain 300 (until_front_at)" in \
        summary["incomplete_reason"]
    assert "hertzchain: error: incomplete run: the run stopped at max_steps = 2000" in cap.err
    assert str(out) in cap.err
    # the result is written and says so
    with h5py.File(out) as f:
        stored = json.loads(f.attrs["summary"])
    assert stored["completed"] is False and stored["stopped_by"] == "max_steps"
    assert "completed: False" in describe(out)


def test_t_end_before_the_front_is_incomplete():
    s = run_scenario(parse_scenario(_wave(until_front_at=300, t_end=2e-4)))
    assert (s["completed"], s["stopped_by"]) == (False, "t_end")
    assert "stopped at t_end = 0.0002 s" in s["incomplete_reason"]


def test_snapshot_never_taken_is_incomplete(tmp_path, capsys):
    # the run stops when the front reaches grain 200 (~0.55 ms); the snapshot at 5 ms
    # would come later
    d = {**_wave(until_front_at=200), "record": {"snapshot_times": [5e-3]}}
    assert main(["run", _toml(d, tmp_path / "s.toml")]) == EXIT_INCOMPLETE
    cap = capsys.readouterr()
    assert "stopped_by                 until_front_at" in cap.out
    assert "completed                  False" in cap.out
    assert "the snapshots ['t=0.005'] were never taken" in cap.err


def test_completed_runs_say_so(tmp_path, capsys):
    s = run_scenario(parse_scenario(_wave(until_front_at=200)))
    assert (s["completed"], s["stopped_by"], s["incomplete_reason"]) == \
        (True, "until_front_at", "")
    toml = _toml({**_wave(t_end=3e-4), "record": {"snapshot_times": [1e-4, 3e-4]}},
                 tmp_path / "s.toml")
    assert main(["run", toml]) == 0
    assert "stopped_by                 t_end" in capsys.readouterr().out


def test_simulation_reports_the_bound_that_stopped_it():
    # Simulation.run said "t_end" whenever t_end was given, also when max_steps came first
    _, _, sim = build_simulation(parse_scenario(_wave()))
    assert sim.run(7.5e-4, max_steps=10, progress=False).stopped_by == "max_steps"
    assert sim.run(7.5e-4, progress=False).stopped_by == "t_end"
    _, _, sim = build_simulation(parse_scenario(_wave()))
    assert C.run_segmented(sim, t_end=7.5e-4, step_limit=25_000, signals=False,
                           interval=1e9) == "max_steps"
    assert sim.steps == 25_000
    assert C.run_segmented(sim, t_end=7.5e-4, signals=False, interval=1e9) == "t_end"


# -- labels -------------------------------------------------------------------------------
@pytest.mark.parametrize(("ar", "ak"), [(0.5, 2.0), (1.0, 1.0)])
def test_no_label_before_the_wave_reaches_the_interface(ar, ak):
    # t_end = 1e-4 s: the wave is still ~70 grains left of the interface
    s = run_scenario(parse_scenario(_wave(ar, ak, t_end=1e-4)))
    assert s["completed"] and not s["separated"]
    assert s["transmitted"] is None and s["reflected"] is None
    assert s["n_transmitted_pulses"] is None
    assert np.isnan(s["front_speed_tr"]) and np.isnan(s["front_speed_re"])
    assert np.isnan(s["separation_fraction"])


def test_labels_once_separated_and_none_means_measured():
    # a uniform chain (alpha = 1): nothing reflects, and the label says so once measured
    s = run_scenario(parse_scenario(_wave(1.0, 1.0)))
    assert s["separated"] and s["reflected"] == "none" and s["Ek_re"] < 1e-9
    assert s["transmitted"] == "squeeze" and s["n_transmitted_pulses"] == 1
    s = run_scenario(parse_scenario(_wave(0.5, 2.0)))
    assert s["separated"] and s["reflected"] in ("compressive", "expansive")
    assert s["transmitted"] in ("fracture", "squeeze") and s["n_transmitted_pulses"] >= 1


def test_cli_prints_absent_labels_as_na(tmp_path, capsys):
    assert main(["run", _toml(_wave(t_end=1e-4), tmp_path / "s.toml")]) == 0
    out = capsys.readouterr().out
    assert "reflected                  n/a" in out and "transmitted                n/a" in out


# -- sweeps --------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                      dashboard_address=":0", silence_logs=logging.ERROR) as cluster, \
            Client(cluster) as c:
        yield c


def test_sweep_records_outcome_and_undefined_labels(tmp_path, client):
    from hertzchain.sweep import read_results, run_sweep

    base = _wave(until_front_at=300)
    spec = {"name": "outcome", "base": base, "sweep": {"mode": "zip", "axes": [
        {"path": "run.max_steps", "values": [2000, 1_000_000]}]}}
    outcome = run_sweep(spec, out=tmp_path / "sw", client=client, progress=False,
                        warmup=None)
    assert (outcome.n_ok, outcome.n_incomplete) == (2, 1)
    res = read_results(outcome.table)
    assert list(res["completed"]) == [0, 1]
    assert list(res["stopped_by"]) == ["max_steps", "until_front_at"]
    assert "max_steps = 2000" in res["incomplete_reason"][0]
    assert res["incomplete_reason"][1] == ""
    # the cut run has no labels ("" in the table), the complete one has
    assert res["transmitted"][0] == "" and res["reflected"][0] == ""
    assert res["n_transmitted_pulses"][0] == -1  # the integer columns' fill value
    assert res["transmitted"][1] in ("fracture", "squeeze", "none")


def test_sweep_exit_status():
    from pathlib import Path

    from hertzchain.sweep.cli import EXIT_ALL_FAILED, EXIT_PENDING, EXIT_SOME_BAD, exit_status
    from hertzchain.sweep.engine import SweepOutcome

    def outcome(ok, failed, pending, incomplete=0):
        return SweepOutcome(Path("d"), Path("d/results.h5"), ok + failed + pending, 0,
                            ok + failed, ok, failed, pending, 1.0, bool(pending),
                            incomplete)

    assert exit_status(outcome(4, 0, 0)) == 0
    assert exit_status(outcome(4, 0, 0, incomplete=1)) == EXIT_SOME_BAD
    assert exit_status(outcome(3, 1, 0)) == EXIT_SOME_BAD
    assert exit_status(outcome(0, 4, 0)) == EXIT_ALL_FAILED  # was 0
    assert exit_status(outcome(1, 1, 2)) == EXIT_PENDING


def test_incomplete_points_are_not_classified():
    from hertzchain.sweep.analysis import classification_agreement
    from hertzchain.sweep.store import SweepResults

    cols = {"id": np.array(["a", "b", "c"], dtype=object),
            "status": np.array(["ok"] * 3, dtype=object),
            "alpha_rho": np.array([0.5, 0.5, 0.5]), "alpha_kn": np.array([2.0, 2.0, 2.0]),
            "transmitted": np.array(["fracture", "", "squeeze"], dtype=object),
            "reflected": np.array(["expansive", "", "expansive"], dtype=object),
            "completed": np.array([1, 1, 0], dtype=np.int8)}
    agr = classification_agreement(SweepResults(cols, {}, {}))
    assert agr.n_classified == 1

