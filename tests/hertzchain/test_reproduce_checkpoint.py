"""``hertzchain reproduce``: checkpoint and resume, bit for bit.

Tiny configurations of the items (their ``QUICK`` defaults patched, in this process, in
the subprocess or in the worker processes), compared with an uninterrupted run
(``checkpoint_interval=None``:
one ``Simulation.run`` call per simulation, the code path of the cached results before
checkpoints): every dataset and attribute of every HDF5 file in ``runs/`` (but the
``wall_time`` attribute) and the ``--json`` output, exactly.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

import hertzchain.reproduce as R
from hertzchain import checkpoint as C
from hertzchain._argtypes import jsonable
from hertzchain.cli import main
from hertzchain.reproduce import fig2, fig6, reproduce, table2
from hertzchain.reproduce.common import Context

REPO = Path(__file__).resolve().parents[2]

# Fig. 6 with one α: two runs of ~1800 grains, WaveAt snapshots and stop event, ~25
# segments each (long enough for a subprocess to be killed in the first run)
FIG6_TINY = {"alphas": (2.0,), "n_left": 300, "lead": 100, "length": 1500, "every": 10,
             "windows": (10, 50, 1470)}
FIG2_TINY = {"n_grains": {1e-3: 1500}, "variants": ()}


def _dump(path: Path) -> dict:
    """Every dataset and attribute of an HDF5 file as bytes (no wall times)."""
    out = {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                out[name] = (str(obj.dtype), obj.shape, np.asarray(obj[()]).tobytes())
            for key, val in obj.attrs.items():
                out[f"{name}@{key}"] = repr(val)

        f.visititems(visit)
        for key, val in f.attrs.items():
            if key == "summary":
                val = json.loads(val)
                val.pop("wall_time", None)  # (a continuum file keeps it apart)
            if key != "wall_time":
                out[f"@{key}"] = repr(val)
    return out


def _assert_same_runs(a: Path, b: Path) -> int:
    """The HDF5 files of two ``runs/`` directories are the same, bit for bit; how many."""
    names = sorted(p.name for p in a.iterdir())
    assert names == sorted(p.name for p in b.iterdir())  # no checkpoint, no temporary
    assert names and all(n.endswith(".h5") for n in names)
    for name in names:
        da, db = _dump(a / name), _dump(b / name)
        assert sorted(da) == sorted(db), name
        assert [k for k in da if da[k] != db[k]] == [], name
    return len(names)


def _interrupt_after_each_checkpoint(monkeypatch) -> list[int]:
    """Send ourselves SIGINT after every checkpoint write (as Ctrl-C would)."""
    real, count = C.write_checkpoint, [0]

    def write(*args, **kwargs):
        out = real(*args, **kwargs)
        count[0] += 1
        os.kill(os.getpid(), signal.SIGINT)
        return out

    monkeypatch.setattr(C, "write_checkpoint", write)
    return count


@pytest.mark.parametrize("item", ["fig2", "fig3"])
def test_interrupt_at_every_segment_and_resume(item, tmp_path, monkeypatch):
    # Ctrl-C after each checkpoint: every call integrates one segment, writes a
    # checkpoint and stops (Interrupted, exit code 130, "rerun ... to resume"); the next
    # call resumes from it.  fig2: running maxima of v and u; fig3: time series.
    # The SIGINT handler is restored to what it was (Python's default_int_handler in a
    # foreground process; SIG_IGN when the suite runs as a background job).
    sigint = signal.getsignal(signal.SIGINT)
    monkeypatch.setattr(fig2, "QUICK", FIG2_TINY)
    ref = reproduce([item], out=tmp_path / "ref", progress=False, report=False,
                    checkpoint_interval=None)
    out = tmp_path / "run"
    if (tmp_path / "ref" / "cache").exists():  # the settled incident wave
        shutil.copytree(tmp_path / "ref" / "cache", out / "cache")
    count = _interrupt_after_each_checkpoint(monkeypatch)
    sessions = 0
    while True:
        sessions += 1
        assert sessions < 200
        try:
            got = reproduce([item], out=out, progress=False, report=False,
                            checkpoint_interval=0.0)
            break
        except C.Interrupted as exc:
            assert exc.exit_code == 130
            assert exc.checkpoint is not None and exc.checkpoint.exists()
            assert f"checkpoint written to {exc.checkpoint}" in str(exc)
            assert "rerun the same command to resume" in str(exc)
    assert sessions >= 4 and count[0] == sessions - 1
    assert signal.getsignal(signal.SIGINT) is sigint
    assert got["items"] == ref["items"]
    assert json.dumps(jsonable(got["items"])) == json.dumps(jsonable(ref["items"]))
    _assert_same_runs(tmp_path / "ref" / "runs", out / "runs")


def test_scenario_runs_resume_and_force_discards(tmp_path, monkeypatch):
    # The runner's runs (Table 2, Fig. 8) are checkpointed beside their file too;
    # --force discards a checkpoint and starts over.
    s = table2.QUICK | {"continuum": False}
    ref = table2.run(Context(tmp_path / "ref", progress=False, checkpoint_interval=None),
                     points=("M",), **s)
    ctx = Context(tmp_path / "run", progress=False, checkpoint_interval=0.0)
    count = _interrupt_after_each_checkpoint(monkeypatch)
    with pytest.raises(C.Interrupted, match="rerun the same command to resume"):
        table2.run(ctx, points=("M",), **s)
    ckpt = next((tmp_path / "run" / "runs").glob("*.ckpt"))
    first = _ckpt_steps(ckpt)
    with pytest.raises(C.Interrupted, match="without --force to resume"):
        table2.run(Context(tmp_path / "run", progress=False, checkpoint_interval=0.0,
                           force=True), points=("M",), **s)
    assert count[0] == 2 and _ckpt_steps(ckpt) == first  # started over: one segment
    with pytest.raises(C.Interrupted):  # resumed: two segments
        table2.run(ctx, points=("M",), **s)
    assert _ckpt_steps(ckpt) == 2 * first
    monkeypatch.undo()
    got = table2.run(ctx, points=("M",), **s)
    assert got[0].discrete == ref[0].discrete and got[0].drift == ref[0].drift
    _assert_same_runs(tmp_path / "ref" / "runs", tmp_path / "run" / "runs")


def test_run_models_reuses_the_finished_file(tmp_path):
    # run_models (the one run path, hertzchain.models.run): computed once, then reused,
    # counted; no checkpoint left; a dict is validated as a scenario
    from hertzchain.reproduce.common import run_models
    from hertzchain.scenario import ScenarioError

    sc = {"chain": {"sections": [{"n": 60}]}, "initial": {"kind": "impact"},
          "run": {"until_front_at": 40}, "record": {"energy_grid": False}}
    ctx = Context(tmp_path, progress=False, checkpoint_interval=0.0)
    first = run_models(ctx, "x", sc)
    again = run_models(ctx, "x", sc)
    path = first.discrete.path
    assert ctx.computed == ctx.reused == [path] and path.parent == ctx.runs
    assert path.name.startswith("x-") and again.discrete.cached
    assert again.simulation.steps == first.simulation.steps > 0
    assert not list(tmp_path.rglob("*.ckpt"))
    with pytest.raises(ScenarioError, match="until_front_at"):
        run_models(ctx, "y", {**sc, "run": {"until_front_at": 60}})


def test_run_models_save_false_checkpoints_but_writes_nothing(tmp_path, monkeypatch):
    # save=False (the items that keep a reduction of the run): checkpointed beside the
    # file name and resumed bit for bit, but the finished run is not written, not
    # counted (path None), and no checkpoint is left
    from hertzchain.reproduce.common import run_models

    sc = {"chain": {"sections": [{"n": 600}]}, "initial": {"kind": "impact"},
          "run": {"until_front_at": 500}, "record": {"energy_every": 50}}
    ref = run_models(Context(tmp_path / "ref", progress=False, checkpoint_interval=None),
                     "x", sc).simulation
    ctx = Context(tmp_path / "run", progress=False, checkpoint_interval=0.0)
    count = _interrupt_after_each_checkpoint(monkeypatch)
    with pytest.raises(C.Interrupted, match="checkpoint written to"):
        run_models(ctx, "x", sc, save=False)
    assert count[0] == 1 and len(list(ctx.runs.glob("*.ckpt"))) == 1
    monkeypatch.undo()
    got = run_models(ctx, "x", sc, save=False)
    assert got.discrete.path is None and got.discrete.completed
    assert ctx.computed == ctx.reused == []
    assert not [p for p in ctx.runs.iterdir() if not p.name.startswith(".")]
    sim = got.simulation
    assert sim.steps == ref.steps > 0 and sim.t == ref.t
    assert np.array_equal(sim.u, ref.u) and np.array_equal(sim.v, ref.v)
    a, b = sim.record.arrays(), ref.record.arrays()
    assert all(np.array_equal(a[k], b[k]) for k in a)


def test_checkpoint_interval_option(tmp_path, capsys):
    with pytest.raises(SystemExit):
        main(["reproduce", "fig3", "--checkpoint-interval", "-1", "--out", str(tmp_path)])
    assert "--checkpoint-interval: must be a finite number >= 0" in capsys.readouterr().err
    with pytest.raises(ValueError, match="checkpoint_interval"):
        Context(tmp_path, checkpoint_interval=float("nan"))


# -- a real process, killed and interrupted -------------------------------------------
def _start(out: Path, *extra: str) -> subprocess.Popen:
    code = ("import sys\nfrom hertzchain.reproduce import fig6\n"
            f"fig6.QUICK = {FIG6_TINY!r}\n"
            "from hertzchain.cli import main\nsys.exit(main(sys.argv[1:]))")
    return subprocess.Popen(
        [sys.executable, "-c", code, "reproduce", "fig6", "--out", str(out),
         "--checkpoint-interval", "0", *extra], cwd=REPO, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True)


def _wait_for_checkpoint(proc, runs: Path, after: float = 0.0, timeout: float = 60
                         ) -> Path:
    """A checkpoint in ``runs`` written after ``after`` (st_mtime) by the running ``proc``."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        for p in runs.glob("*.ckpt") if runs.exists() else ():
            try:
                if p.stat().st_mtime > after:
                    return p
            except FileNotFoundError:
                pass
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.005)
    raise AssertionError("no checkpoint written")


def test_real_process_sigkill_sigint_resume(tmp_path, monkeypatch):
    # `hertzchain reproduce fig6 --json --checkpoint-interval 0` (tiny Fig. 6) in a real
    # process: (1) SIGKILL at a random moment after its first checkpoint appeared; (2)
    # the same command without --json (messages on stderr) resumes and gets SIGINT after
    # its next checkpoint: exit 130, a checkpoint on disk, "rerun ... to resume"; (3) the
    # same command completes.  Its --json output and every HDF5 file equal an
    # uninterrupted run's, bit for bit.
    monkeypatch.setattr(fig6, "QUICK", FIG6_TINY)
    ref = reproduce(["fig6"], out=tmp_path / "ref", progress=False, report=False,
                    checkpoint_interval=None)
    ref_json = json.dumps(jsonable(ref["items"]["fig6"]), allow_nan=False)
    out = tmp_path / "run"
    runs = out / "runs"
    shutil.copytree(tmp_path / "ref" / "cache", out / "cache")  # the settled wave
    rng = np.random.default_rng(int(time.time()))

    proc = _start(out, "--json")
    ckpt = _wait_for_checkpoint(proc, runs)
    time.sleep(float(rng.uniform(0.0, 0.2)))
    proc.send_signal(signal.SIGKILL)
    proc.communicate(timeout=60)
    assert proc.returncode == -signal.SIGKILL
    assert not list(runs.glob("fig6-passages-*")), "the run finished before the kill"
    steps_killed = _ckpt_steps(ckpt)
    assert steps_killed > 0

    proc = _start(out)
    _wait_for_checkpoint(proc, runs, after=ckpt.stat().st_mtime)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert f"resuming from {ckpt}: t = " in err
    assert "interrupted by SIGINT" in err and "rerun the same command to resume" in err
    assert ckpt.exists() and _ckpt_steps(ckpt) > steps_killed

    proc = _start(out, "--json")
    stdout, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    assert stdout.strip() == ref_json
    assert _assert_same_runs(tmp_path / "ref" / "runs", runs) == 2
    assert not [p for p in out.rglob("*") if p.name.endswith((".tmp", ".ckpt"))]


def test_two_workers_sigint_checkpoint_and_resume(tmp_path, monkeypatch):
    # `reproduce(["fig4", "fig6"], workers=2)` with Fig. 6 tiny in the worker processes:
    # SIGINT (here, as Ctrl-C or a kill would send it) once Fig. 6's first checkpoint
    # is on disk: the workers' runs stop, each after writing its checkpoint, and the
    # call raises Interrupted (exit status 130, "rerun ... to resume"); the same call
    # again resumes from the checkpoint; its numbers and every HDF5 file equal an
    # uninterrupted run's, bit for bit.
    monkeypatch.setattr(fig6, "QUICK", FIG6_TINY)
    ref = reproduce(["fig4", "fig6"], out=tmp_path / "ref", progress=False, report=False,
                    checkpoint_interval=None, workers=1)
    out = tmp_path / "run"
    runs = out / "runs"
    shutil.copytree(tmp_path / "ref" / "cache", out / "cache")  # the settled wave

    def task(*args):  # the Dask task, with Fig. 6 tiny in the worker
        import importlib

        importlib.import_module("hertzchain.reproduce.fig6").QUICK = FIG6_TINY
        return importlib.import_module("hertzchain.reproduce")._remote_task(*args)

    monkeypatch.setattr(R, "_remote_task", task)

    def interrupt():
        end = time.monotonic() + 120
        while time.monotonic() < end and not list(runs.glob("fig6-*.ckpt")):
            time.sleep(0.005)
        os.kill(os.getpid(), signal.SIGINT)

    sigint = signal.getsignal(signal.SIGINT)
    killer = threading.Thread(target=interrupt)
    killer.start()
    try:
        with pytest.raises(C.Interrupted) as info:
            reproduce(["fig4", "fig6"], out=out, progress=False, report=False,
                      checkpoint_interval=0.0, workers=2)
    finally:
        killer.join()
    exc = info.value
    assert exc.exit_code == 130 and exc.checkpoint is not None
    assert exc.checkpoint.exists() and exc.checkpoint.parent == runs
    assert "rerun the same command to resume" in str(exc)
    steps = _ckpt_steps(exc.checkpoint)
    assert steps > 0 and signal.getsignal(signal.SIGINT) is sigint
    assert not list(runs.glob("fig6-passages-*")), "Fig. 6 finished before the signal"

    got = reproduce(["fig4", "fig6"], out=out, progress=False, report=False,
                    checkpoint_interval=0.0, workers=2)
    assert json.dumps(jsonable(got["items"])) == json.dumps(jsonable(ref["items"]))
    assert sorted(p.name for p in got["computed"] + got["reused"]) == \
        sorted(p.name for p in ref["computed"])
    assert _assert_same_runs(tmp_path / "ref" / "runs", runs) == 4
    assert not [p for p in out.rglob("*") if p.name.endswith((".tmp", ".ckpt"))]


def _ckpt_steps(path: Path) -> int:
    """Steps reached by the checkpoint at ``path`` (read back with its own key)."""
    with h5py.File(path, "r") as f:
        key = f.attrs["checkpoint_key"]
    return C.read_checkpoint(path, key)[0].steps
