"""``reproduce(workers=2)``: the items in two lanes, one in a forked worker process.

What must hold (issue 13): the numbers, the files and the computed/reused counts are
those of one process, bit for bit and in report order; an interrupted or failing worker
is reported by the calling process; bad ``workers``/``threads`` are clear errors.
The lanes are set to two cheap items (Figs. 3 and 4, a few seconds) for the real run;
the rest uses a stand-in ``run_item`` (inherited by the forked worker).
"""

import json
import multiprocessing
import os
import signal
import time
from contextlib import nullcontext

import pytest

import hertzchain.reproduce as R
from hertzchain.checkpoint import Interrupted
from hertzchain.reproduce import reproduce
from hertzchain.reproduce.command import jsonable
from hertzchain.sweep.engine import default_workers

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="needs fork")


def test_lanes_split_and_order():
    # one process: Fig. 8 and Table 2 first (R.FIRST: the peak memory), then report order
    assert R.lanes(list(R.ITEMS), 1) == [["fig8", "table2", "fig2", "fig3", "fig4", "fig5",
                                          "fig6", "fig7", "validity"]]
    assert R.lanes(["fig2", "table2"], 1) == [["table2", "fig2"]]
    # two processes: the worker forked after Fig. 3, then Fig. 8 and Table 2 here
    assert R.LANES[1][0] == "fig3" and R.LANES[1][1:3] == R.FIRST
    assert R.lanes(list(R.ITEMS), 2) == [list(R.LANES[0]), list(R.LANES[1])]
    assert R.lanes(["fig2", "fig7"], 2) == [["fig7"], ["fig2"]]
    assert R.lanes(["fig8", "table2"], 2) == [["fig8", "table2"]]  # one lane: serial
    # every item in exactly one lane; Table 2 in Fig. 8's lane, after it (it reuses
    # Fig. 8's point files)
    assert sorted(R.LANES[0] + R.LANES[1]) == sorted(R.ITEMS)
    lane = next(la for la in R.LANES if "fig8" in la)
    assert lane.index("fig8") < lane.index("table2")


def test_full_lanes_split_and_order():
    # --full: Fig. 5 alone in the worker; the same rules as --quick's lanes (every item
    # once, Table 2 after Fig. 8 in one lane, Fig. 3 first in the calling process)
    assert R.lanes(list(R.ITEMS), 2, "full") == [list(R.FULL_LANES[0]),
                                                 list(R.FULL_LANES[1])]
    assert R.FULL_LANES[0] == ("fig5",)
    assert R.lanes(["fig2", "fig5"], 2, "full") == [["fig5"], ["fig2"]]
    assert R.lanes(["fig5", "fig7"], 2, "full") == [["fig5"], ["fig7"]]
    # one process: FIRST (Fig. 8, Table 2: the memory peak on the lowest floor) first,
    # then the rest in report order, as in --quick
    assert R.lanes(list(R.ITEMS), 1, "full") == [
        list(R.FIRST) + [n for n in R.ITEMS if n not in R.FIRST]]
    assert sorted(R.FULL_LANES[0] + R.FULL_LANES[1]) == sorted(R.ITEMS)
    assert R.FULL_LANES[1][0] == "fig3"
    lane = next(la for la in R.FULL_LANES if "fig8" in la)
    assert lane.index("fig8") < lane.index("table2")


def test_two_workers_same_numbers_files_and_counts(tmp_path, monkeypatch):
    # the real items, fig4 in the worker: JSON byte for byte, counts and files in
    # report order, as one process
    one = reproduce(["fig3", "fig4"], out=tmp_path / "one", progress=False, report=False,
                    workers=1)
    monkeypatch.setattr(R, "LANES", (("fig4",), ("fig3",)))
    two = reproduce(["fig3", "fig4"], out=tmp_path / "two", progress=False, report=True,
                    workers=2)
    assert json.dumps(jsonable(two["items"])) == json.dumps(jsonable(one["items"]))
    assert [r.name for r in two["runs"]] == ["fig3", "fig4"]
    assert [p.name for p in two["computed"]] == [p.name for p in one["computed"]]
    assert not two["reused"] and not one["reused"]
    assert set(two["context"].timings) == {"fig3", "fig4"}
    assert all(p.exists() for p in two["report"])
    # a second call reuses every file, in both lanes
    again = reproduce(["fig3", "fig4"], out=tmp_path / "two", progress=False,
                      report=False, workers=2)
    assert not again["computed"]
    assert [p.name for p in again["reused"]] == [p.name for p in one["computed"]]
    assert again["items"] == two["items"]


def _fake(fail):
    def run_item(ctx, name):
        if name == fail[0]:
            raise fail[1]
        path = ctx.runs / f"{name}.h5"
        ctx.computed.append(path)
        return R.ItemRun(name, None, {"pid": os.getpid()}, [], {"n": len(name)},
                         computed=[path])
    return run_item


def test_worker_runs_in_another_process_results_in_report_order(tmp_path, monkeypatch):
    monkeypatch.setattr(R, "run_item", _fake((None, None)))
    got = reproduce(["fig2", "fig5", "fig6", "fig7"], out=tmp_path, progress=False,
                    report=False, workers=2)
    assert [r.name for r in got["runs"]] == ["fig2", "fig5", "fig6", "fig7"]
    pids = {r.name: r.result["pid"] for r in got["runs"]}
    assert pids["fig2"] == pids["fig6"] == os.getpid() != pids["fig5"] == pids["fig7"]
    assert [p.name for p in got["computed"]] == ["fig2.h5", "fig5.h5", "fig6.h5", "fig7.h5"]
    assert got["runs"][1].module is R.importlib.import_module("hertzchain.reproduce.fig5")


def test_worker_interrupted_is_raised_here(tmp_path, monkeypatch):
    exc = Interrupted(signal.SIGINT, tmp_path / "x.ckpt", 1.5e-3, 42, note="resume so")
    monkeypatch.setattr(R, "run_item", _fake(("fig7", exc)))
    with pytest.raises(Interrupted) as info:
        reproduce(["fig2", "fig7"], out=tmp_path, progress=False, report=False, workers=2)
    e = info.value
    assert (e.signum, e.checkpoint, e.t, e.steps) == (signal.SIGINT, tmp_path / "x.ckpt",
                                                        1.5e-3, 42)
    assert str(e) == str(exc)


def test_worker_error_is_raised_here(tmp_path, monkeypatch):
    monkeypatch.setattr(R, "run_item", _fake(("fig5", ValueError("bad fig5"))))
    with pytest.raises(ValueError, match="bad fig5"):
        reproduce(["fig2", "fig5"], out=tmp_path, progress=False, report=False, workers=2)


def test_error_here_stops_the_worker(tmp_path, monkeypatch):
    # the calling process fails while the worker is busy: after the grace time the
    # worker gets SIGTERM and is reaped, and the error is raised
    fake = _fake(("fig6", RuntimeError("bad fig6")))

    def run_item(ctx, name):
        if name == "fig5":
            time.sleep(60)
        return fake(ctx, name)

    monkeypatch.setattr(R, "run_item", run_item)
    monkeypatch.setattr(R, "_JOIN_GRACE", 0.5)
    start = time.monotonic()
    with pytest.raises(RuntimeError, match="bad fig6"):
        reproduce(["fig2", "fig5", "fig6"], out=tmp_path, progress=False, report=False,
                  workers=2)
    assert time.monotonic() - start < 30
    assert not multiprocessing.active_children()


@pytest.mark.parametrize("kwargs, match", [
    ({"workers": 3}, "workers must be 1 or 2"),
    ({"workers": 0}, "workers must be 1 or 2"),
    ({"workers": True}, "workers must be 1 or 2"),
    ({"workers": 2, "threads": 2}, "threads=1"),
    ({"workers": 2, "mode": "full", "threads": 2}, "threads=1"),
])
def test_bad_workers(tmp_path, kwargs, match):
    with pytest.raises(ValueError, match=match):
        reproduce(["fig2", "fig5"], out=tmp_path, progress=False, report=False, **kwargs)


def test_default_is_one_process_and_cli_option(tmp_path, monkeypatch, capsys):
    # QUICK_WORKERS (2, capped at the cores): two lanes by default; --workers 2 forks
    from hertzchain.cli import main

    seen = []
    real = R._run_parallel

    def spy(*args):
        seen.append("parallel")
        return real(*args)

    monkeypatch.setattr(R, "_run_parallel", spy)
    monkeypatch.setattr(R, "run_item", _fake((None, None)))
    monkeypatch.setattr("hertzchain.reproduce.report.write_report", lambda *a: ())
    reproduce(["fig2", "fig5"], out=tmp_path, progress=False, report=False)
    assert seen == ["parallel"] * (min(R.QUICK_WORKERS, default_workers()) == 2)
    seen.clear()
    # --full: FULL_WORKERS (2, capped at the cores) on one kernel thread each; one
    # process if more threads are asked for
    threads = []
    monkeypatch.setattr(R, "kernel_threads", lambda t: (threads.append(t), nullcontext())[1])
    reproduce(["fig2", "fig5"], mode="full", out=tmp_path, progress=False, report=False)
    assert seen == ["parallel"] * (min(R.FULL_WORKERS, default_workers()) == 2)
    assert set(threads) == ({1} if seen else {None})
    seen.clear()
    threads.clear()
    reproduce(["fig2", "fig5"], mode="full", out=tmp_path, progress=False, report=False,
              threads=2)
    assert seen == [] and set(threads) == {2}
    threads.clear()
    # items of one lane only (e.g. --full fig5): one process, on numba's threads
    reproduce(["fig5"], mode="full", out=tmp_path, progress=False, report=False)
    assert seen == [] and threads == [None]
    assert main(["reproduce", "fig2", "fig5", "--json", "--workers", "2", "--out",
                 str(tmp_path)]) == 0
    assert json.loads(capsys.readouterr().out) == {"fig2": {"n": 4}, "fig5": {"n": 4}}
    assert seen == ["parallel"]
    with pytest.raises(SystemExit):
        main(["reproduce", "--workers", "3", "--out", str(tmp_path)])


def test_compile_seconds_count_real_compiles_only(tmp_path):
    # the summary's "numba spent N s compiling": numba's compile events, which fire for a
    # compilation and not for a call of an already compiled (or cache-loaded) kernel
    import numba

    from hertzchain.reproduce.common import Context

    @numba.njit
    def fresh(x):  # a new function: its first call compiles
        return x * 2.0 + 1.0

    ctx = Context(tmp_path, progress=False)
    with R._compile_timer(ctx):
        assert fresh(1.0) == 3.0
    first = ctx.compile_seconds
    assert first > 0.0
    with R._compile_timer(ctx):
        assert fresh(2.0) == 5.0  # compiled already: no event
    assert ctx.compile_seconds == first


def test_idle_lane_takes_fig5_cases_same_numbers_and_counts(tmp_path, monkeypatch, capsys):
    # Fig. 5 in the worker, the calling lane idle after Fig. 3: it runs the cases the
    # worker has not started (last first) and the worker reuses them; the numbers, the
    # files and the computed/reused counts are those of one process
    from hertzchain.reproduce import fig5

    monkeypatch.setattr(fig5, "QUICK", {"n_grains": 1200, "interface": 900,
                                        "snapshot": 1150, "lead": 100})
    one = reproduce(["fig3", "fig5"], out=tmp_path / "one", progress=False, report=False,
                    workers=1)
    monkeypatch.setattr(R, "LANES", (("fig5",), ("fig3",)))
    capsys.readouterr()
    two = reproduce(["fig3", "fig5"], out=tmp_path / "two", progress=True, report=False,
                    workers=2)
    here = capsys.readouterr().err
    assert "fig5 (d): run here" in here  # the worker starts with (a): (d) is free
    assert json.dumps(jsonable(two["items"])) == json.dumps(jsonable(one["items"]))
    assert sorted(p.name for p in two["computed"]) == sorted(p.name for p in one["computed"])
    assert not two["reused"] and not one["reused"]
    assert two["context"].claims is None  # the claim files are gone with the call
    again = reproduce(["fig3", "fig5"], out=tmp_path / "two", progress=False,
                      report=False, workers=2)
    assert not again["computed"] and again["items"] == two["items"]


def test_claims(tmp_path):
    # claim_if_free takes a part only if nobody claimed it; claim waits for the holder
    import threading

    from hertzchain.reproduce.common import Context, claim, claim_if_free

    ctx = Context(tmp_path, claims=tmp_path)
    with claim_if_free(ctx, "x") as mine:
        assert mine
        got = []
        t = threading.Thread(target=lambda: got.append(_wait_claim(ctx, "x")))
        t.start()
        t.join(0.3)
        assert t.is_alive() and not got  # blocked while the part is held
    t.join(10)
    assert got == [True]
    with claim_if_free(ctx, "x") as mine:  # claimed (and done) before: not free
        assert not mine
    with claim(ctx, "y"), claim_if_free(ctx, "y") as mine:
        assert not mine
    with claim_if_free(Context(tmp_path), "z") as mine:  # one process: nothing to share
        assert not mine


def _wait_claim(ctx, key):
    from hertzchain.reproduce.common import claim

    with claim(ctx, key):
        return True
