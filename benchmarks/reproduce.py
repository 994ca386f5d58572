"""Wall time, CPU time and memory of ``hertzchain reproduce --quick`` (or ``--full``).

What is measured: the command itself (``python -m hertzchain reproduce --quick --json
--out <fresh dir> [--workers W]``), warm (numba's kernel cache filled by a first run of
each variant, which is not timed), into a fresh output directory each time, so every
simulation is computed.  A variant is a worker count (``--workers``, several allowed;
default: the command's own default) of this checkout's code or, with ``--against DIR``,
of another checkout's (run with ``PYTHONPATH=DIR``, e.g. the main branch): the variants
run in alternating order (A B B A ...), so that drifts of the machine's load hit them
alike, and the ratio of each variant's median wall time to the first one's is printed.
Memory: the largest process's peak RSS, exact (the kernel's high-water mark,
``ru_maxrss`` of ``wait4``, which covers the reaped worker processes: what
``/usr/bin/time -v`` reports), and, sampled every 0.1 s over the whole process tree,
the sum of PSS (shared pages split between the processes: the physical memory the tree
uses).  Every run's ``--json`` output must be byte-identical to the first one's, and to
``--reference`` if given (else the script fails).

The machine may be shared: the CPU model and the one-minute load average before each run
are printed; compare only ratios within one run of this script.

Usage::

    python benchmarks/reproduce.py                           # 2 rounds, default workers
    python benchmarks/reproduce.py --workers 1 2 --rounds 1 --skip-warmup
    python benchmarks/reproduce.py --against ../main         # this code against main's
    python benchmarks/reproduce.py --full --rounds 1 --skip-warmup
    python benchmarks/reproduce.py --reference main.json     # numbers unchanged?
    python benchmarks/reproduce.py --write-docs              # also into docs/benchmarks.md
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import psutil
from _docs import ROOT, markdown_table, section, write_section
from _machine import cpu_name


def run_once(out: Path, workers: int | None, mode: str = "quick",
             code: Path = ROOT) -> dict:
    """One ``reproduce --<mode>`` of the code in ``code`` into ``out``: wall, CPU, memory."""
    cmd = [sys.executable, "-m", "hertzchain", "reproduce", f"--{mode}", "--json", "--out",
           str(out)] + ([] if workers is None else ["--workers", str(workers)])
    env = dict(os.environ, PYTHONPATH=str(code))
    load = os.getloadavg()[0]
    before = os.times()
    t0 = time.perf_counter()
    with tempfile.TemporaryFile() as out_file:
        p = subprocess.Popen(cmd, stdout=out_file, stderr=subprocess.DEVNULL, env=env)
        top = psutil.Process(p.pid)
        pss = 0
        while True:
            # (reaped here, not by Popen: wait4 gives the kernel's high-water mark)
            pid, status, usage = os.wait4(p.pid, os.WNOHANG)
            if pid:
                break
            try:
                mem = [q.memory_full_info() for q in [top, *top.children(recursive=True)]]
                pss = max(pss, sum(m.pss for m in mem))
            except psutil.Error:  # (a process exited mid-sample)
                pass
            time.sleep(0.1)
        p.returncode = os.waitstatus_to_exitcode(status)
        out_file.seek(0)
        stdout = out_file.read().decode()
    wall = time.perf_counter() - t0
    after = os.times()
    if p.returncode:
        raise SystemExit(f"reproduce failed (exit {p.returncode}): PYTHONPATH={code} "
                         f"{' '.join(cmd)}")
    cpu = (after.children_user + after.children_system
           - before.children_user - before.children_system)
    return {"wall": wall, "cpu": cpu, "pss_sum": pss, "hwm": usage.ru_maxrss * 1024,
            "load": load, "json": stdout}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=2,
                    help="rounds, each variant once per round, in alternating order "
                         "(default 2)")
    ap.add_argument("--workers", type=int, nargs="+", default=[None], metavar="W",
                    help="worker counts to measure (default: the command's default)")
    ap.add_argument("--against", metavar="DIR",
                    help="also run another checkout's code (PYTHONPATH=DIR), e.g. main's")
    ap.add_argument("--skip-warmup", action="store_true",
                    help="do not run each code once first to fill numba's kernel cache")
    ap.add_argument("--full", action="store_true", help="measure reproduce --full")
    ap.add_argument("--reference", metavar="FILE",
                    help="the --json output of a reference version (e.g. main: "
                         "hertzchain reproduce --quick --json > FILE); fail unless equal")
    ap.add_argument("--write-docs", action="store_true",
                    help="write the table into docs/benchmarks.md (section "
                         "'reproduce-quick' or 'reproduce-full')")
    args = ap.parse_args(argv)
    mode = "full" if args.full else "quick"
    codes = [("this", ROOT)] + ([("against", Path(args.against).resolve())]
                                if args.against else [])
    variants = [(name, code, w) for name, code in codes for w in args.workers]
    label = {v: f"{'this checkout' if v[0] == 'this' else v[1].name}, "
                f"{'default' if v[2] is None else v[2]} workers" for v in variants}
    load0 = os.getloadavg()[0]
    print(f"reproduce --{mode}; CPU: {cpu_name()}; load average before {load0:.1f}")
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench-reproduce-") as tmp:
        if not args.skip_warmup:
            for name, code in codes:
                run_once(Path(tmp) / f"warmup-{name}", None, mode, code)
        order = [v for r in range(args.rounds)
                 for v in (variants if r % 2 == 0 else variants[::-1])]
        for k, v in enumerate(order):
            r = run_once(Path(tmp) / f"run{k}", v[2], mode, v[1]) | {"variant": v}
            rows.append(r)
            print(f"  {label[v]}: wall {r['wall']:6.1f} s  CPU {r['cpu']:6.1f} s  peak MB: "
                  f"largest process {r['hwm'] / 1e6:4.0f}, PSS sum {r['pss_sum'] / 1e6:4.0f}"
                  f"  (load before {r['load']:.1f})", flush=True)
    if any(r["json"] != rows[0]["json"] for r in rows):
        raise SystemExit("FAIL: the --json output differs between runs")
    print("--json output byte-identical in every run")
    if args.reference is not None:
        if Path(args.reference).read_text() != rows[0]["json"]:
            raise SystemExit(f"FAIL: the --json output differs from {args.reference}")
        print(f"--json output byte-identical to {args.reference}")
    med = {v: statistics.median(r["wall"] for r in rows if r["variant"] == v)
           for v in variants}
    load1 = os.getloadavg()[0]
    ratio = "; ".join(f"{label[v]} {med[v]:.1f} s ({med[v] / med[variants[0]]:.2f}×)"
                      for v in variants)
    print(f"median wall: {ratio}; load average after {load1:.1f}")
    table = markdown_table(
        ["code, workers", "load before", "wall s", "CPU s", "largest process peak RSS (MB)",
         "PSS over all processes (MB)"],
        [[label[r["variant"]], f"{r['load']:.1f}", f"{r['wall']:.1f}", f"{r['cpu']:.1f}",
          f"{r['hwm'] / 1e6:.0f}", f"{r['pss_sum'] / 1e6:.0f}"] for r in rows])
    print(table)
    if args.write_docs:
        notes = (f"`hertzchain reproduce --{mode} --json --out <fresh dir> [--workers W]`, "
                 "warm kernel cache"
                 + (f" (DIR: a checkout of other code, here {codes[1][1].name}, run with "
                    "`PYTHONPATH=DIR`)" if args.against else "")
                 + ", every simulation computed; rows in the order run "
                 "(alternating, so that load drifts hit every variant alike); median wall "
                 f"(ratio to the first variant): {ratio}.  The load is the one-minute "
                 "load average before each run.  Peak RSS is the kernel's high-water mark "
                 "(`ru_maxrss`, worker processes included); PSS is sampled every 0.1 s "
                 "(pages shared between processes counted once).  The `--json` output "
                 "was byte-identical in every run.")
        # (the command as the docs show it: the paths given are outside the repository)
        argv, sys.argv = sys.argv, [
            {"--against": "DIR", "--reference": "FILE"}.get(prev, a)
            for prev, a in zip([None, *sys.argv[:-1]], sys.argv, strict=True)]
        try:
            body = section(table, load=(load0, load1), notes=notes)
        finally:
            sys.argv = argv
        write_section(f"reproduce-{mode}", body)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
