"""``reproduce(workers=N)``: the items' tasks on a local Dask cluster of worker processes.

What must hold: the numbers, the files and the computed/reused counts are those of one
process, bit for bit and in report order, for every worker count; Fig. 5's cases are
tasks of their own; a task's error, or its worker's death, is a clear error naming the
task; bad ``workers`` are clear errors.  The real items run on tiny sizes: the workers
are new processes, so the sizes are set there by a wrapper of the Dask task
(:func:`_in_workers`) as well as here (for ``workers=1``).
"""

import importlib
import json
import os

import pytest

import hertzchain.reproduce as R
from hertzchain._argtypes import jsonable
from hertzchain.cli import main
from hertzchain.reproduce import Task, WorkerDied, plan, reproduce
from hertzchain.reproduce.common import Context

FIG5_TINY = {"n_grains": 1200, "interface": 900, "snapshot": 1150, "lead": 100}


def _in_workers(monkeypatch, patches, before=None):
    """Set ``patches`` ((module, attribute, value), ...) here and in every worker process.

    The Dask task is wrapped by a function pickled by value (a closure), which sets them
    in the worker and then runs the worker's own task; ``before(task)``, if given, runs
    first there (to fail or die on a task).
    """
    for mod, attr, value in patches:
        monkeypatch.setattr(importlib.import_module(mod), attr, value)

    def task(*args):
        import importlib

        for mod, attr, value in patches:
            setattr(importlib.import_module(mod), attr, value)
        if before is not None:
            before(args[1])
        return importlib.import_module("hertzchain.reproduce")._remote_task(*args)

    monkeypatch.setattr(R, "_remote_task", task)


def test_plan_order_parts_and_needs(tmp_path):
    tasks = plan(R.ITEMS, Context(tmp_path))
    assert sorted(R.ORDER) == sorted(R.ITEMS)
    keys = [t.key for t in tasks]
    assert len(set(keys)) == len(keys)
    # Fig. 5: a task per case, then the task that combines them and draws the figure
    assert [t for t in tasks if t.name == "fig5"] == [
        *(Task("fig5", "part", c) for c in "abcd"), Task("fig5", "combine")]
    # Table 2 after Fig. 8 (it reuses its point files); otherwise in ORDER
    assert keys.index("table2") > keys.index("fig8")
    items = list(dict.fromkeys(t.name for t in tasks))
    assert [n for n in items if n != "table2"] == [n for n in R.ORDER if n != "table2"]
    assert [t.key for t in plan(["table2", "fig2"], Context(tmp_path))] == ["fig2", "table2"]
    assert [t.key for t in plan(["fig8", "table2"], Context(tmp_path))] == ["fig8", "table2"]


def test_one_and_two_workers_same_numbers_files_and_counts(tmp_path, monkeypatch):
    # the real items (Fig. 5 on 1,200 grains): JSON byte for byte, files and counts in
    # report order, with one worker (this process) and two (worker processes)
    _in_workers(monkeypatch, [("hertzchain.reproduce.fig5", "QUICK", FIG5_TINY)])
    items = ["fig4", "fig5"]
    one = reproduce(items, out=tmp_path / "one", progress=False, report=False, workers=1)
    two = reproduce(items, out=tmp_path / "two", progress=False, report=True, workers=2)
    assert one["workers"] == 1 and two["workers"] == 2
    assert json.dumps(jsonable(two["items"])) == json.dumps(jsonable(one["items"]))
    assert [r.name for r in two["runs"]] == items
    names = [p.name for p in one["computed"]]
    assert len(names) == 2 + 2 * 4  # Fig. 4: two runs; Fig. 5: discrete and continuum
    assert [p.name for p in two["computed"]] == names and not two["reused"]
    assert [p.parent for p in two["computed"]] == [tmp_path / "two" / "runs"] * len(names)
    assert set(two["context"].timings) == set(items)
    assert all(p.exists() for p in two["report"])
    assert (tmp_path / "two" / "figures" / "fig5.png").stat().st_size > 1000
    # a second call reuses every file
    again = reproduce(items, out=tmp_path / "two", progress=False, report=False, workers=2)
    assert not again["computed"] and [p.name for p in again["reused"]] == names
    assert again["items"] == two["items"]


def _local_fake_task():
    """The stand-in task as a local function: Dask sends it to its workers by value
    (cloudpickle), where this test module is not importable (a fresh clone's tests/
    directory is not on the workers' sys.path)."""

    def _fake_task(template, task, inputs, threads, position, start):
        """A stand-in task: the worker's pid as result, parts passed on in order."""
        import os
        import time

        from hertzchain.reproduce import TaskOutcome

        time.sleep(0.3)
        if task.kind == "part":
            return TaskOutcome(task, (task.part, os.getpid()), computed=[f"{task.key}.h5"])
        parts = [i.value for i in inputs]
        return TaskOutcome(task, ({"pid": os.getpid(), "parts": parts, "threads": threads},
                                  [], {"n": len(task.name)}), computed=[f"{task.key}.h5"])

    return _fake_task


_fake_task = _local_fake_task()


def test_tasks_run_in_worker_processes_results_in_report_order(tmp_path, monkeypatch):
    monkeypatch.setattr(R, "_remote_task", _fake_task)
    got = reproduce(["fig2", "fig5", "fig6", "fig7"], out=tmp_path, progress=False,
                    report=False, workers=2)
    assert [r.name for r in got["runs"]] == ["fig2", "fig5", "fig6", "fig7"]
    pids = {r.result["pid"] for r in got["runs"]}
    fig5 = got["runs"][1].result
    pids |= {pid for _, pid in fig5["parts"]}
    assert os.getpid() not in pids and len(pids) == 2  # both workers used
    assert [c for c, _ in fig5["parts"]] == list("abcd")
    assert {r.result["threads"] for r in got["runs"]} == {1}
    assert got["computed"] == ["fig2.h5", "fig5:a.h5", "fig5:b.h5", "fig5:c.h5", "fig5:d.h5",
                               "fig5:combine.h5", "fig6.h5", "fig7.h5"]
    assert got["runs"][1].module is importlib.import_module("hertzchain.reproduce.fig5")


def test_task_error_is_raised_here_naming_the_task(tmp_path, monkeypatch):
    def fail(task):
        if task.key == "fig5:b":
            raise ValueError("bad fig5")

    _in_workers(monkeypatch, [("hertzchain.reproduce.fig5", "QUICK", FIG5_TINY)], fail)
    with pytest.raises(ValueError, match="bad fig5") as info:
        reproduce(["fig5"], out=tmp_path, progress=False, report=False, workers=2)
    assert "(in the reproduce task fig5:b)" in info.value.__notes__


def test_worker_death_is_a_clean_error_naming_the_item(tmp_path, monkeypatch, capsys):
    def die(task):
        if task.name == "fig4":
            import os

            os._exit(3)

    _in_workers(monkeypatch, [], die)
    with pytest.raises(WorkerDied, match="the worker process running fig4 died"):
        reproduce(["fig3", "fig4"], out=tmp_path / "api", progress=False, report=False,
                  workers=2)
    # the command: "hertzchain: error: ..." and exit status 2
    assert main(["reproduce", "fig4", "fig3", "--workers", "2", "--json", "--out",
                 str(tmp_path / "cli")]) == 2
    err = capsys.readouterr().err
    assert "hertzchain: error: the worker process running fig4 died" in err
    assert "rerun the same command" in err


def test_workers_default_and_bad_values(tmp_path, monkeypatch, capsys):
    seen = []

    def on_cluster(ctx, tasks, workers, threads, positions, start):
        seen.append((workers, threads))
        return {t.key: _fake_task(ctx, t, [], threads, "", start) for t in tasks}

    monkeypatch.setattr(R, "_on_cluster", on_cluster)
    monkeypatch.setattr(R, "_in_process", lambda ctx, tasks, threads, *a: seen.append(
        (1, threads)) or {t.key: _fake_task(ctx, t, [], threads, "", 0) for t in tasks})
    monkeypatch.setattr("hertzchain.sweep.engine.default_workers", lambda: 4)
    monkeypatch.setattr("hertzchain.reproduce.report.write_report", lambda *a: ())
    # default: the cores (4 here), at most the tasks (2, and 5 for Fig. 5's cases)
    reproduce(["fig3", "fig4"], out=tmp_path, progress=False, report=False)
    reproduce(["fig5"], out=tmp_path, progress=False, report=False)
    reproduce(["fig4"], out=tmp_path, progress=False, report=False)  # one task: here
    # any N >= 1; one kernel thread per worker (--full with one worker: numba's count)
    reproduce(["fig4"], out=tmp_path, progress=False, report=False, workers=7)
    reproduce(["fig4"], mode="full", out=tmp_path, progress=False, report=False, workers=1)
    assert seen == [(2, 1), (4, 1), (1, 1), (7, 1), (1, None)]
    for bad in (0, -1, True, 1.5):
        with pytest.raises(ValueError, match="workers must be an integer >= 1"):
            reproduce(["fig4"], out=tmp_path, progress=False, report=False, workers=bad)
    with pytest.raises(SystemExit):
        main(["reproduce", "--workers", "0", "--out", str(tmp_path)])
    assert "--workers: must be an integer >= 1" in capsys.readouterr().err
    assert main(["reproduce", "fig2", "fig5", "--json", "--workers", "3", "--out",
                 str(tmp_path)]) == 0
    assert json.loads(capsys.readouterr().out) == {"fig2": {"n": 4}, "fig5": {"n": 4}}
    assert seen[-1] == (3, 1)


def test_compile_seconds_count_real_compiles_only(tmp_path):
    # the summary's "numba spent N s of CPU compiling": numba's compile events, which fire for a
    # compilation and not for a call of an already compiled (or cache-loaded) kernel
    import numba

    @numba.njit
    def fresh(x):  # a new function: its first call compiles
        return x * 2.0 + 1.0

    import time

    ctx = Context(tmp_path, progress=False)
    cpu0 = time.thread_time()
    with R._compile_timer(ctx):
        assert fresh(1.0) == 3.0
    cpu = time.thread_time() - cpu0
    first = ctx.compile_seconds
    # CPU time of this thread's compile, never more than the thread's CPU over the block
    assert 0.0 < first <= cpu
    with R._compile_timer(ctx):
        assert fresh(2.0) == 5.0  # compiled already: no event
    assert ctx.compile_seconds == first
