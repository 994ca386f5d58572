"""Wall time, CPU time and memory of ``hertzchain reproduce --quick`` or ``--full``, 1 or 2 workers.

What is measured: the command itself (``python -m hertzchain reproduce --quick --json
--out <fresh dir> --workers W``), warm (numba's kernel cache filled by a first run,
which is not timed), into a fresh output directory each time, so every simulation is
computed.  Rounds alternate ``--workers 1`` and ``--workers 2`` (ABBA…) so that the
machine's load drifts equally over both; the ratio of the median walls is printed.
Memory: the largest process's peak RSS, exact (the kernel's high-water mark, ``ru_maxrss``
of ``wait4``: what ``/usr/bin/time -v`` reports), and, sampled every 0.1 s over the whole
process tree (the command and its forked worker), the sum of RSS (counts pages the two
processes share twice), of PSS (shared pages split between the processes: the physical
memory the tree uses) and of USS, and the largest single RSS.  Every run's ``--json``
output must be byte-identical to the first one's, and to ``--reference`` if given (else
the script fails).

The machine is shared: the CPU model and the load average before and after are printed;
compare only ratios within one run.

``--full`` measures ``reproduce --full`` the same way (its two workers are
:data:`hertzchain.reproduce.FULL_LANES`; a run takes minutes, so ``--rounds 1`` is the
practical choice).  ``--write-docs`` writes the table into its section of
``docs/benchmarks.md`` (``reproduce-quick`` or ``reproduce-full``).

Usage::

    python benchmarks/reproduce.py                 # 2 rounds (1, 2, 2, 1)
    python benchmarks/reproduce.py --rounds 1 --skip-warmup
    python benchmarks/reproduce.py --full --rounds 1 --skip-warmup
    python benchmarks/reproduce.py --reference main.json   # numbers unchanged?
    python benchmarks/reproduce.py --write-docs    # also into docs/benchmarks.md
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
from _docs import markdown_table, section, write_section
from _machine import cpu_name


def run_once(out: Path, workers: int, mode: str = "quick") -> dict:
    """One ``reproduce --<mode>`` into ``out``: wall, CPU (s), memory peaks (bytes), JSON."""
    cmd = [sys.executable, "-m", "hertzchain", "reproduce", f"--{mode}", "--json", "--out",
           str(out), "--workers", str(workers)]
    before = os.times()
    t0 = time.perf_counter()
    with tempfile.TemporaryFile() as out_file:
        p = subprocess.Popen(cmd, stdout=out_file, stderr=subprocess.DEVNULL)
        top = psutil.Process(p.pid)
        peak = {"rss_sum": 0, "pss_sum": 0, "uss_sum": 0, "rss_max1": 0}
        while True:
            # (reaped here, not by Popen: wait4 gives the kernel's high-water mark)
            pid, status, usage = os.wait4(p.pid, os.WNOHANG)
            if pid:
                break
            try:
                mem = [q.memory_full_info() for q in [top, *top.children(recursive=True)]]
            except psutil.Error:  # (a process exited mid-sample)
                time.sleep(0.1)
                continue
            peak["rss_sum"] = max(peak["rss_sum"], sum(m.rss for m in mem))
            peak["pss_sum"] = max(peak["pss_sum"], sum(m.pss for m in mem))
            peak["uss_sum"] = max(peak["uss_sum"], sum(m.uss for m in mem))
            peak["rss_max1"] = max(peak["rss_max1"], max(m.rss for m in mem))
            time.sleep(0.1)
        p.returncode = os.waitstatus_to_exitcode(status)
        out_file.seek(0)
        stdout = out_file.read().decode()
    wall = time.perf_counter() - t0
    after = os.times()
    if p.returncode:
        raise SystemExit(f"reproduce failed (exit {p.returncode}): {' '.join(cmd)}")
    cpu = (after.children_user + after.children_system
           - before.children_user - before.children_system)
    # ru_maxrss (kB): the largest peak RSS of the command and its (reaped) worker,
    # exact, where the 0.1 s samples may miss a short peak
    return {"workers": workers, "wall": wall, "cpu": cpu, **peak,
            "hwm": usage.ru_maxrss * 1024, "json": stdout}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=2, help="ABBA rounds (default 2)")
    ap.add_argument("--skip-warmup", action="store_true",
                    help="do not run once first to fill numba's kernel cache")
    ap.add_argument("--full", action="store_true", help="measure reproduce --full")
    ap.add_argument("--reference", metavar="FILE",
                    help="the --json output of a reference version (e.g. main: "
                         "hertzchain reproduce --quick --json > FILE); fail unless equal")
    ap.add_argument("--write-docs", action="store_true",
                    help="write the table into docs/benchmarks.md (section "
                         "'reproduce-quick' or 'reproduce-full')")
    args = ap.parse_args(argv)
    mode = "full" if args.full else "quick"
    load0 = os.getloadavg()[0]
    print(f"reproduce --{mode}; CPU: {cpu_name()}; load average before {load0:.1f}")
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench-reproduce-") as tmp:
        if not args.skip_warmup:
            run_once(Path(tmp) / "warmup", 1, mode)
        order = [w for r in range(args.rounds) for w in ((1, 2) if r % 2 == 0 else (2, 1))]
        for k, w in enumerate(order):
            rows.append(run_once(Path(tmp) / f"run{k}", w, mode))
            r = rows[-1]
            print(f"  workers={w}: wall {r['wall']:6.1f} s  CPU {r['cpu']:6.1f} s  "
                  f"peak MB: largest process (VmHWM) {r['hwm'] / 1e6:4.0f}; sampled: PSS "
                  f"sum {r['pss_sum'] / 1e6:4.0f}, USS sum {r['uss_sum'] / 1e6:4.0f}, RSS "
                  f"sum {r['rss_sum'] / 1e6:4.0f}, largest RSS {r['rss_max1'] / 1e6:4.0f}  "
                  f"(load {os.getloadavg()[0]:.1f})", flush=True)
    if any(r["json"] != rows[0]["json"] for r in rows):
        raise SystemExit("FAIL: the --json output differs between runs")
    print("--json output byte-identical in every run")
    if args.reference is not None:
        if Path(args.reference).read_text() != rows[0]["json"]:
            raise SystemExit(f"FAIL: the --json output differs from {args.reference}")
        print(f"--json output byte-identical to {args.reference}")
    med = {w: statistics.median(r["wall"] for r in rows if r["workers"] == w) for w in (1, 2)}
    load1 = os.getloadavg()[0]
    ratio = (f"median wall: workers=1 {med[1]:.1f} s, workers=2 {med[2]:.1f} s; ratio "
             f"{med[1] / med[2]:.2f}x")
    print(f"{ratio}; load average after {load1:.1f}")
    table = markdown_table(
        ["`--workers`", "wall s", "CPU s", "largest process peak RSS (MB)",
         "PSS over all processes (MB)"],
        [[r["workers"], f"{r['wall']:.1f}", f"{r['cpu']:.1f}", f"{r['hwm'] / 1e6:.0f}",
          f"{r['pss_sum'] / 1e6:.0f}"] for r in rows])
    print(table)
    if args.write_docs:
        notes = (f"`hertzchain reproduce --{mode} --json --out <fresh dir> --workers W`, "
                 "warm kernel cache, every simulation computed; rows in the order run "
                 f"(alternating, so that load drifts hit both counts alike); {ratio}.  "
                 "Peak RSS is the kernel's high-water mark (`ru_maxrss`); PSS is sampled "
                 "every 0.1 s (pages shared by the two processes counted once).  The "
                 "`--json` output was byte-identical in every run.")
        write_section(f"reproduce-{mode}", section(table, load=(load0, load1), notes=notes))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
