"""Checkpoint, resume and determinism, bit for bit.

Every comparison here is exact: the bytes of every HDF5 dataset and attribute of the
output file (``_dump``), and the canonical JSON of the summary without ``wall_time``
(the only key allowed to differ).  ``test_naive_segmentation_differs`` shows that the
comparison can fail: without dropping the duplicate energy-monitor sample at segment
boundaries the record differs.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

import discrete
from hertzchain import checkpoint as C
from hertzchain._argtypes import jsonable
from hertzchain.cache import canonical_json
from hertzchain.cli import main
from hertzchain.runner import build_simulation, run_scenario, summarise
from hertzchain.scenario import parse_scenario

REPO = Path(__file__).resolve().parents[1]

SCENARIOS = {
    # precompressed exact wave through an interface: snapshots, time series, auto grid
    "exact": {"chain": {"delta0_over_d": 1e-3, "sections": [
        {"n": 150}, {"n": 200, "alpha_rho": 0.5, "alpha_kn": 2.0}]},
        "initial": {"kind": "exact_wave", "center": 75, "velocity_max": 0.0822},
        "run": {"t_end": 7.5e-4},
        "record": {"snapshot_times": [1e-4, 3e-4], "time_series_grains": [149, 150, 300]}},
    # sonic vacuum impact with gaps, stop event, an energy row every 7 steps
    "impact": {"chain": {"sections": [{"n": 120}, {"n": 150, "alpha_rho": 0.2}]},
               "initial": {"kind": "impact", "v0": 1.0}, "run": {"until_front_at": 250},
               "record": {"time_series_grains": [119, 120], "energy_every": 7}},
    # the impact with rtol: refined maxima (on with rtol) and their per-grain search
    # state across segment ends, where chunks close (c2 = 0, discrete.kernels)
    "impact_rtol": {"chain": {"sections": [{"n": 400}, {"n": 500, "alpha_rho": 0.2}]},
                    "initial": {"kind": "impact", "v0": 1.0},
                    "run": {"until_front_at": 850, "rtol": 1e-4},
                    "record": {"time_series_grains": [119, 120], "energy_every": 7}},
    # cut (settled) wave at delta0 = 0 into a stiffer section, t_end and a snapshot
    "cut": {"chain": {"sections": [{"n": 150}, {"n": 200, "alpha_kn": 5.0}]},
            "initial": {"kind": "cut_wave", "center": 60}, "run": {"t_end": 1.5e-3},
            "record": {"snapshot_times": [2e-4]}},
}

# long enough (~1 s, 1.2e6 steps) for a subprocess to be killed midway
KILL_TOML = """name = "kill-test"
[chain]
delta0_over_d = 1e-3
[[chain.sections]]
n = 600
[[chain.sections]]
n = 600
alpha_rho = 2.0
alpha_kn = 0.5
[initial]
kind = "exact_wave"
center = 80
velocity_max = 0.0822
[run]
t_end = 0.06
[record]
snapshot_times = [5e-4, 2e-3, 1e-2]
energy_every = 10000
"""


def _dump(path) -> dict:
    """Every dataset and attribute of an HDF5 file as bytes (summary without wall_time)."""
    out = {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                data = obj[()]
                out[name] = (str(obj.dtype), obj.shape, np.asarray(data).tobytes())
            for key, val in obj.attrs.items():
                out[f"{name}@{key}"] = repr(val)

        f.visititems(visit)
        for key, val in f.attrs.items():
            if key == "summary":
                summary = json.loads(val)
                summary.pop("wall_time")
                val = canonical_json(summary)
            out[f"@{key}"] = repr(val)
    return out


def _assert_same_file(a, b) -> None:
    da, db = _dump(a), _dump(b)
    assert sorted(da) == sorted(db)
    different = [k for k in da if da[k] != db[k]]
    assert not different, different


def _same_summary(a: dict, b: dict) -> bool:
    a, b = dict(a), dict(b)
    a.pop("wall_time")
    b.pop("wall_time")
    return canonical_json(a) == canonical_json(b)


def _sim_state(sim) -> dict:
    rec = sim.record
    out = {k: v.tobytes() for k, v in rec.arrays().items()}
    out.update(u=sim.u.tobytes(), v=sim.v.tobytes(), a=sim.a.tobytes(), steps=sim.steps,
               vmax=None if rec.vmax is None else rec.vmax.tobytes(),
               umax=None if rec.umax is None else rec.umax.tobytes(),
               **{name: None if getattr(rec, name) is None else getattr(rec, name).tobytes()
                  for name in ("vmax_refined", "vmax_time", "peak_state")},
               snaps=[(s.label, s.step, s.u.tobytes(), s.v.tobytes()) for s in rec.snapshots],
               drift=sim.energy_drift)
    return out


def _until(sc):
    return None if sc.run.until_front_at is None else discrete.WaveAt(sc.run.until_front_at)


@pytest.mark.parametrize("name", sorted(SCENARIOS))
def test_segmented_run_is_bitwise_identical(name, tmp_path):
    # One Simulation.run call vs segments of segment_steps() with a checkpoint written
    # after each (interval 0): u, v, a, maxima, snapshots, every record array, the drift
    # and the summary must agree bit for bit.
    sc = parse_scenario(SCENARIOS[name])
    chain, init, ref = build_simulation(sc)
    ref.run(sc.run.t_end, until=_until(sc), max_steps=sc.run.max_steps, progress=False)
    chain2, init2, sim = build_simulation(sc)
    C.run_segmented(sim, t_end=sc.run.t_end, until=_until(sc), step_limit=sc.run.max_steps,
                    checkpoint=tmp_path / "x.ckpt", key="k", interval=0.0)
    assert sim.steps > 2 * C.segment_steps(sim)  # at least three segments
    # an rtol run keeps refined maxima (compared below with their search state)
    assert (sim.record.vmax_refined is not None) == (sc.run.rtol is not None)
    assert _sim_state(sim) == _sim_state(ref)
    amp = 1.0
    assert canonical_json(summarise(chain, sim, amp)) == canonical_json(
        summarise(chain, ref, amp))


def test_naive_segmentation_differs(monkeypatch):
    # Control: without dropping the closing monitor sample of each segment the record
    # is not that of the uninterrupted run (so the comparison above can fail).
    sc = parse_scenario(SCENARIOS["exact"])
    _, _, ref = build_simulation(sc)
    ref.run(sc.run.t_end, progress=False)
    monkeypatch.setattr(C, "_drop_closing_sample", lambda sim: None)
    _, _, sim = build_simulation(sc)
    C.run_segmented(sim, t_end=sc.run.t_end)
    a, b = _sim_state(sim), _sim_state(ref)
    assert a["u"] == b["u"] and a["vmax"] == b["vmax"]
    assert a["monitor_t"] != b["monitor_t"]


def _interrupt_after(monkeypatch, writes: int) -> None:
    """Send ourselves SIGINT after the ``writes``-th checkpoint write of each session."""
    real = C.write_checkpoint
    count = [0]

    def write(*args, **kwargs):
        out = real(*args, **kwargs)
        count[0] += 1
        if count[0] == writes:
            os.kill(os.getpid(), signal.SIGINT)
        return out

    monkeypatch.setattr(C, "write_checkpoint", write)
    return count


@pytest.mark.parametrize("name", ["exact", "impact"])
def test_interrupt_at_every_segment_and_resume(name, tmp_path, monkeypatch):
    # SIGINT after the first checkpoint of every session: each session does one segment,
    # checkpoints, stops with Interrupted (exit code 130); the next one resumes from the
    # loaded checkpoint.  The final file equals the uninterrupted run's bit for bit.
    # The SIGINT handler ends as it was (SIG_IGN in a background job).
    sigint = signal.getsignal(signal.SIGINT)
    sc = parse_scenario(SCENARIOS[name])
    ref = run_scenario(sc, out=tmp_path / "ref.h5")
    out = tmp_path / "run.h5"
    sessions = 0
    while True:
        sessions += 1
        count = _interrupt_after(monkeypatch, 1)
        try:
            summary = run_scenario(sc, out=out, checkpoint_interval=0.0)
            break
        except C.Interrupted as exc:
            assert exc.exit_code == 130 and exc.checkpoint == C.checkpoint_path(out)
            assert "rerun the same command to resume" in str(exc)
            assert count[0] == 1  # the signal came during a write: no second one needed
            assert not out.exists() and C.checkpoint_path(out).exists()
        assert sessions < 50
    assert sessions >= 3
    assert signal.getsignal(signal.SIGINT) is sigint
    assert _same_summary(summary, ref)
    assert not C.checkpoint_path(out).exists()
    _assert_same_file(out, tmp_path / "ref.h5")


def test_checkpoint_of_another_scenario_is_refused(tmp_path, monkeypatch, capsys):
    sc = parse_scenario(SCENARIOS["exact"])
    out = tmp_path / "run.h5"
    _interrupt_after(monkeypatch, 1)
    with pytest.raises(C.Interrupted):
        run_scenario(sc, out=out, checkpoint_interval=0.0)
    other = parse_scenario({**SCENARIOS["exact"], "run": {"t_end": 8e-4}})
    with pytest.raises(C.CheckpointError, match="checkpoint of a different run.*--force"):
        run_scenario(other, out=out, checkpoint_interval=0.0)
    # through the CLI: exit 2 with the message; --force discards it and runs
    toml = tmp_path / "other.toml"
    toml.write_text(_toml(SCENARIOS["exact"]).replace("t_end = 0.00075", "t_end = 0.0008"))
    assert main(["run", str(toml), "--out", str(out), "--checkpoint-interval", "0"]) == 2
    assert "different run" in capsys.readouterr().err
    assert main(["run", str(toml), "--out", str(out), "--force", "--json"]) == 0
    assert "removed the checkpoint" in capsys.readouterr().err
    assert out.exists() and not C.checkpoint_path(out).exists()


@pytest.mark.parametrize("damage", ["truncate", "garbage", "remove_dataset"])
def test_damaged_checkpoint_gives_clear_error(damage, tmp_path, monkeypatch):
    sc = parse_scenario(SCENARIOS["exact"])
    out = tmp_path / "run.h5"
    _interrupt_after(monkeypatch, 1)
    with pytest.raises(C.Interrupted):
        run_scenario(sc, out=out, checkpoint_interval=0.0)
    ck = C.checkpoint_path(out)
    _damage(ck, damage)
    with pytest.raises(C.CheckpointError) as err:
        run_scenario(sc, out=out, checkpoint_interval=0.0)
    assert str(ck) in str(err.value) and "--force" in str(err.value)


def _damage(path: Path, how: str) -> None:
    if how == "truncate":
        size = path.stat().st_size
        with path.open("r+b") as fh:
            fh.truncate(size // 2)
    elif how == "garbage":
        path.write_bytes(np.random.default_rng(0).bytes(4096))
    else:
        with h5py.File(path, "a") as f:
            del f["state/v"]


def _toml(d: dict) -> str:
    """A scenario dict as TOML (enough for the dicts of this file)."""
    lines = []
    for table in ("chain", "initial", "run", "record"):
        t = d.get(table, {})
        lines.append(f"[{table}]")
        for k, v in t.items():
            if k != "sections":
                lines.append(f"{k} = {json.dumps(v)}")
        for s in t.get("sections", []):
            lines.append("[[chain.sections]]")
            lines += [f"{k} = {json.dumps(v)}" for k, v in s.items()]
    return "\n".join(lines) + "\n"


def _start(toml: Path, out: Path) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "hertzchain", "run", str(toml), "--out", str(out), "--json",
         "--checkpoint-interval", "0"], cwd=REPO, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True)


def _wait_for_new_checkpoint(proc, ckpt: Path, after: float, timeout: float = 60) -> None:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if ckpt.exists() and ckpt.stat().st_mtime > after:
            return
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.01)
    raise AssertionError("no checkpoint written")


def test_real_process_sigint_then_sigkill_then_resume(tmp_path):
    # A real `hertzchain run` process: (1) SIGINT after its first checkpoint -> exit 130,
    # a message saying how to resume; (2) the rerun resumes and is SIGKILLed at a random
    # moment after its next checkpoint; (3) the rerun completes.  The output file equals
    # an uninterrupted in-process run's in every dataset and attribute, bit for bit.
    toml = tmp_path / "kill.toml"
    toml.write_text(KILL_TOML)
    sc = parse_scenario(__import__("tomllib").loads(KILL_TOML))
    ref = tmp_path / "ref.h5"
    ref_summary = run_scenario(sc, out=ref)
    out = tmp_path / "run.h5"
    ckpt = C.checkpoint_path(out)
    rng = np.random.default_rng(int(time.time()))

    proc = _start(toml, out)
    _wait_for_new_checkpoint(proc, ckpt, 0.0)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "interrupted by SIGINT" in err and "rerun the same command to resume" in err
    assert not out.exists()
    steps_1 = C.read_checkpoint(ckpt, C.run_key(sc.to_dict()))[0].steps

    proc = _start(toml, out)
    _wait_for_new_checkpoint(proc, ckpt, ckpt.stat().st_mtime)
    time.sleep(float(rng.uniform(0.0, 0.4)))
    proc.send_signal(signal.SIGKILL)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == -signal.SIGKILL
    assert "resuming from" in err
    assert not out.exists(), "the run finished before the kill: make it longer"
    steps_2 = C.read_checkpoint(ckpt, C.run_key(sc.to_dict()))[0].steps
    assert steps_2 > steps_1

    proc = _start(toml, out)
    stdout, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    assert "resuming from" in err
    # `hertzchain run` prints the runner's summary and, after it, the other models' keys
    cli = json.loads(stdout)  # strict JSON: NaN is null
    assert _same_summary({k: cli[k] for k in ref_summary if k in cli}, jsonable(ref_summary))
    assert not ckpt.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
    _assert_same_file(out, ref)


def test_two_runs_are_bitwise_identical(tmp_path):
    sc = parse_scenario(SCENARIOS["impact"])
    a = run_scenario(sc, out=tmp_path / "a.h5")
    b = run_scenario(sc, out=tmp_path / "b.h5")
    assert _same_summary(a, b)
    _assert_same_file(tmp_path / "a.h5", tmp_path / "b.h5")


def test_one_and_two_threads_are_bitwise_identical(tmp_path):
    import inspect

    import numba

    if "threads" not in inspect.signature(discrete.Simulation).parameters:
        pytest.skip("Simulation has no threads option yet")
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba has a single thread")
    sc = parse_scenario(SCENARIOS["exact"])
    a = run_scenario(sc, out=tmp_path / "a.h5", threads=1)
    b = run_scenario(sc, out=tmp_path / "b.h5", threads=2, checkpoint_interval=0.0)
    assert _same_summary(a, b)
    _assert_same_file(tmp_path / "a.h5", tmp_path / "b.h5")


def test_signal_after_the_integration_still_writes_the_output(tmp_path, monkeypatch):
    # Ctrl-C while the summary is computed: the output is completed first, then the
    # run reports the interruption (exit code 130 in the CLI).
    import hertzchain.measure as R  # (the runner's summary is the measurement's)

    sigint = signal.getsignal(signal.SIGINT)

    real = R.summarise

    def summarise_then_signal(*args, **kwargs):
        os.kill(os.getpid(), signal.SIGINT)
        return real(*args, **kwargs)

    monkeypatch.setattr(R, "summarise", summarise_then_signal)
    out = tmp_path / "run.h5"
    with pytest.raises(C.Interrupted, match="the run had finished: results written to"):
        run_scenario(parse_scenario(SCENARIOS["exact"]), out=out, checkpoint_interval=300.0)
    monkeypatch.setattr(R, "summarise", real)
    run_scenario(parse_scenario(SCENARIOS["exact"]), out=tmp_path / "ref.h5")
    _assert_same_file(out, tmp_path / "ref.h5")
    assert signal.getsignal(signal.SIGINT) is sigint
