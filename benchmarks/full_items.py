"""CPU and wall time of each ``hertzchain reproduce --full`` item, one process per item.

What is measured: ``python -m hertzchain reproduce --full --json --workers 1 --out <fresh
dir> ITEM`` (one kernel thread, ``NUMBA_NUM_THREADS=1``, as in a lane) for each item
(default: all but Fig. 5, i.e. the calling process's lane of
:data:`hertzchain.reproduce.FULL_LANES`), warm (numba's kernel cache filled by a
previous run of this checkout), into a fresh output directory, so every simulation is
computed.  CPU time is the child's and its children's user + system time (``wait4``:
any process an item starts is included; ``--full`` runs Fig. 7 in-process, its
``backend="sweep"`` would start Dask workers), the figure the lanes share on a loaded
2-core machine; the wall time is printed beside it with the load average.  With
``--baseline-tree DIR`` each item is run from that checkout too (interleaved: A B for
the first item, B A for the second, ...), and the ``--json`` trees of both are compared
(:func:`compare`): the largest relative change of a number, and how many other leaves
(strings such as Fig. 7's labels, booleans, nulls) differ or exist on one side only.

The machine is shared: the CPU model and the load average are printed; compare only
ratios within one run.

Usage::

    python benchmarks/full_items.py          # every item but fig5
    python benchmarks/full_items.py fig2 fig6 --baseline-tree ../hertzchain-main
    python benchmarks/full_items.py --save before.json      # then, after a change:
    python benchmarks/full_items.py --before before.json
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _machine import cpu_name

DEFAULT_ITEMS = ("fig3", "fig2", "fig4", "fig6", "fig7", "fig8", "table2", "validity")


def run_item(tree: Path, item: str, out: Path) -> dict:
    """One item of ``reproduce --full`` from checkout ``tree``: wall, CPU (s), JSON numbers."""
    cmd = [sys.executable, "-m", "hertzchain", "reproduce", "--full", "--json", "--out",
           str(out), "--workers", "1", item]
    # one kernel thread, as in a lane of the two-worker run (FULL_WORKERS); with more, the
    # threaded kernel's spinning threads would count as CPU time
    env = dict(os.environ, PYTHONPATH=str(tree), NUMBA_NUM_THREADS="1")
    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    with tempfile.TemporaryFile() as out_file:
        p = subprocess.Popen(cmd, stdout=out_file, stderr=subprocess.DEVNULL, env=env,
                             cwd=tree)
        _, status, usage = os.wait4(p.pid, 0)
        out_file.seek(0)
        stdout = out_file.read().decode()
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status):
        raise SystemExit(f"reproduce failed: {' '.join(cmd)} (PYTHONPATH={tree})")
    # (wait4's rusage covers the child and its reaped descendants, if it starts any)
    cpu = usage.ru_utime + usage.ru_stime
    numbers = json.loads(stdout)  # (one item: its numbers at the top level)
    return {"wall": wall, "cpu": cpu, "load": load, "numbers": numbers.get(item, numbers)}


def _leaves(obj, prefix=""):
    """(path, value) of every leaf of a JSON tree (numbers, strings, booleans, nulls)."""
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _leaves(v, f"{prefix}/{k}")
    elif isinstance(obj, list):
        for k, v in enumerate(obj):
            yield from _leaves(v, f"{prefix}/{k}")
    else:
        yield prefix, obj


def _is_number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def compare(new: dict, old: dict) -> tuple[float, str, int, str, int]:
    """How two ``--json`` trees differ, leaf by leaf (paths ``/key/index/...``).

    Returns
    -------
    worst, where : float, str
        The largest relative change |new - old| / |old| of a number present in both, and
        its path ("-" if none changed).  NaN against a finite number, and an infinity
        against anything else, count as ``inf``; NaN against NaN as no change.
    n_other, other_where : int, str
        How many other leaves present in both differ (strings such as Fig. 7's
        labels, booleans, nulls, or a number against a non-number), and the first path.
    n_one_side : int
        How many leaves exist in one tree only.
    """
    a, b = dict(_leaves(new)), dict(_leaves(old))
    worst, where, n_other, other_where = 0.0, "-", 0, "-"
    for k in sorted(a.keys() & b.keys()):
        x, y = a[k], b[k]
        if _is_number(x) and _is_number(y):
            x, y = float(x), float(y)
            if x == y or (x != x and y != y):
                continue
            finite = abs(x) < float("inf") and abs(y) < float("inf")
            rel = abs(x - y) / max(abs(y), 1e-300) if finite else float("inf")
            if rel > worst:
                worst, where = rel, k
        elif _is_number(x) or _is_number(y) or type(x) is not type(y) or x != y:
            n_other += 1
            if n_other == 1:
                other_where = k
    return worst, where, n_other, other_where, len(a.keys() ^ b.keys())


def _changes(rel: float, where: str, n_other: int, other_where: str, n_one_side: int) -> str:
    """The printed summary of :func:`compare`."""
    return (f"largest relative change of a number {rel:.2e} ({where})"
            + (f"; {n_other} other leaves differ (first {other_where})" if n_other else "")
            + (f"; {n_one_side} leaves only on one side" if n_one_side else ""))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("items", nargs="*", default=list(DEFAULT_ITEMS))
    ap.add_argument("--baseline-tree", type=Path, metavar="DIR",
                    help="another checkout (e.g. main) run item by item beside this one")
    ap.add_argument("--save", type=Path, metavar="FILE", help="write the rows as JSON")
    ap.add_argument("--before", type=Path, metavar="FILE",
                    help="a --save file of an earlier run (e.g. before a change): print the "
                         "CPU ratio and the largest change of a number per item against it")
    args = ap.parse_args(argv)
    before = json.loads(args.before.read_text()) if args.before else {}
    here = Path(__file__).resolve().parents[1]
    print(f"reproduce --full, one item per process; CPU: {cpu_name()}; load average "
          f"{os.getloadavg()[0]:.1f}", flush=True)
    trees = [("this", here)] + ([("base", args.baseline_tree.resolve())]
                                if args.baseline_tree else [])
    rows = {}
    with tempfile.TemporaryDirectory(prefix="bench-full-items-") as tmp:
        for i, item in enumerate(args.items):
            # alternate which checkout runs first, so neither always meets the same load
            for k, (name, tree) in enumerate(trees if i % 2 == 0 else trees[::-1]):
                r = run_item(tree, item, Path(tmp) / f"{name}-{item}-{k}")
                rows[(item, name)] = r
                print(f"  {item:9s} {name}: CPU {r['cpu']:6.1f} s  wall {r['wall']:6.1f} s  "
                      f"(load {r['load']:.1f})", flush=True)
            old = before.get(f"{item}|this")
            if old:
                new = rows[(item, "this")]
                print(f"  {item:9s} against --before: CPU {old['cpu']:.1f} -> {new['cpu']:.1f} s "
                      f"({old['cpu'] / new['cpu']:.2f}x); "
                      + _changes(*compare(new["numbers"], old["numbers"])), flush=True)
            if args.baseline_tree:
                new, old = rows[(item, "this")], rows[(item, "base")]
                print(f"  {item:9s} CPU ratio base/this {old['cpu'] / new['cpu']:.2f}x; "
                      + _changes(*compare(new["numbers"], old["numbers"])), flush=True)
    tot = {n: sum(r["cpu"] for (i, m), r in rows.items() if m == n) for n, _ in trees}
    print("total CPU: " + ", ".join(f"{n} {c:.1f} s" for n, c in tot.items())
          + f"; load average after {os.getloadavg()[0]:.1f}")
    if args.save:
        args.save.write_text(json.dumps({f"{i}|{n}": r for (i, n), r in rows.items()},
                                        indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
