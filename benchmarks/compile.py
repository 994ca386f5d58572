"""First-run compilation of the kernels: what a cold numba cache costs, against the targets.

**The first run** (targets :data:`TARGET_FIRST_RUN_WALL`, :data:`TARGET_REPRODUCE_COMPILE`):
``hertzchain run`` of a 500-grain impact (running maxima, the front reaching grain 400:
the energy grid, an event, the energy monitor) in a fresh interpreter with an empty
``NUMBA_CACHE_DIR``, timed as a whole process — wall (``time.perf_counter`` around the
child) and CPU (``resource.getrusage(RUSAGE_CHILDREN)``, the steadier figure on a
shared machine) — with the CPU time of numba's outermost ``"numba:compile"`` events
inside it and the largest compiled kernels.  With ``--baseline-tree DIR`` (a checkout
of other code, e.g. ``git worktree add /tmp/old HEAD~3``) the same runs alternate
round by round between that code and this one, so that load changes hit both alike,
and the ratios are printed.  ``--reproduce`` also times the first
``hertzchain reproduce --quick`` on an empty cache and reads the compile time it
states ("numba spent N s of CPU compiling kernels", summed over its worker processes).

**Per family**: a fresh interpreter with an empty ``NUMBA_CACHE_DIR`` runs two small
scenarios through ``hertzchain run`` — a precompressed two-section chain with the
continuum's Eq. 4, then the same at δ0 = 0 with Eq. 7 — and sums, per kernel family
(:data:`theory.jitcache.KERNEL_FAMILIES`) and scenario, the wall and CPU time of numba's
outermost ``"numba:compile"`` events (fired only on a cache miss).  The last column is
the duration the run announces before compiling (``KERNEL_FAMILIES``); a second,
warm process must compile nothing.

    python benchmarks/compile.py                 # 1 round
    python benchmarks/compile.py --rounds 3      # medians over 3 cold processes
    python benchmarks/compile.py --baseline-tree /tmp/old --rounds 3
    python benchmarks/compile.py --reproduce     # also the first reproduce --quick
    python benchmarks/compile.py --write-docs    # also into docs/benchmarks.md
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

from _docs import markdown_table, section, write_section
from _machine import cpu_name
from _scenarios import impact_toml

from theory.jitcache import KERNEL_FAMILIES

SCENARIO = """\
name = "{name}"
[chain]
delta0_over_d = {delta0}
[[chain.sections]]
n = 200
[[chain.sections]]
n = 200
alpha_rho = 2.0
[initial]
kind = "exact_wave"
center = 100
velocity_max = {v}
[run]
t_end = 1e-4
[models]
continuum = "{eq}"
nodes_per_grain = 3
"""

FIRST_RUN = impact_toml(500, 400)

TARGET_FIRST_RUN_WALL = 10.0
"""The first ``hertzchain run`` of a 500-grain scenario on an empty kernel cache, s wall."""

TARGET_REPRODUCE_COMPILE = 20.0
"""numba's compiling in the first ``reproduce --quick``, s summed over its processes."""

_TIMER = textwrap.dedent("""
    import json, sys, threading, time
    from numba.core import event
    from hertzchain.cli import main

    totals, local = {}, threading.local()  # (module, function): [wall s, CPU s]

    class Timer(event.Listener):
        # numba's top-level compiles (a callee's compile is inside its caller's)
        def on_start(self, ev):
            depth = getattr(local, "depth", 0)
            if depth == 0:
                py = ev.data["dispatcher"].py_func
                name = py.__qualname__.split("<locals>.")[-1].split("_L")[0]
                local.start = (py.__module__, name, time.perf_counter(), time.process_time())
            local.depth = depth + 1

        def on_end(self, ev):
            local.depth -= 1
            if local.depth == 0:
                mod, name, wall, cpu = local.start
                w, c = totals.get((mod, name), (0.0, 0.0))
                totals[(mod, name)] = (w + time.perf_counter() - wall,
                                       c + time.process_time() - cpu)

    event.register("numba:compile", Timer())
""")
"""A child's prelude: every top-level numba compile timed, by module and function."""

FIRST_CHILD = _TIMER + textwrap.dedent("""
    if main(["run", sys.argv[1], "--json"]) != 0:
        raise SystemExit("hertzchain run failed")
    print(json.dumps({f"{m}.{n}": c for (m, n), (_, c) in totals.items()}), file=sys.stderr)
""")

CASES = (("precompressed, Eq. 4", dict(name="eq4", delta0=1e-3, v=0.05, eq="eq4")),
         ("δ0 = 0, Eq. 7", dict(name="eq7", delta0=0.0, v=0.5, eq="eq7")))

CHILD = _TIMER + textwrap.dedent("""
    from theory.jitcache import KERNEL_FAMILIES

    out = {}
    for case, toml in json.loads(sys.argv[1]):
        totals.clear()
        if main(["run", toml, "--json"]) != 0:
            raise SystemExit(f"hertzchain run {toml} failed")
        for (mod, _), (w, c) in totals.items():
            fam = mod.split(".")[0]
            if fam in KERNEL_FAMILIES:
                w0, c0 = out.get((case, fam), (0.0, 0.0))
                out[(case, fam)] = (w0 + w, c0 + c)
    print(json.dumps([[c, m, w, p] for (c, m), (w, p) in out.items()]), file=sys.stderr)
""")


def one_process(tmp: Path, cache: Path) -> dict[tuple[str, str], tuple[float, float]]:
    """Run the cases in one fresh interpreter with ``cache``; {(case, family): (wall, cpu)}."""
    cases = []
    for label, fields in CASES:
        path = tmp / f"{fields['name']}.toml"
        path.write_text(SCENARIO.format(**fields))
        cases.append((label, str(path)))
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    p = subprocess.run([sys.executable, "-c", CHILD, json.dumps(cases)], env=env,
                       cwd=tmp, capture_output=True, text=True)
    if p.returncode:
        raise SystemExit(f"the child failed ({p.returncode}):\n{p.stderr[-3000:]}")
    return {(c, m): (w, cpu) for c, m, w, cpu in json.loads(p.stderr.strip().splitlines()[-1])}


def _env(tree: Path | None, cache: Path) -> dict:
    """The child's environment: an empty kernel cache, the code of ``tree`` (None: ours)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["NUMBA_CACHE_DIR"] = str(cache)
    root = tree if tree is not None else Path(__file__).resolve().parent.parent
    env["PYTHONPATH"] = os.pathsep.join([str(root)] + (
        [env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    return env


def first_run(tmp: Path, tree: Path | None, tag: str) -> dict:
    """One first run on an empty cache: wall, CPU, compile CPU and its largest kernels."""
    toml = tmp / "impact500.toml"
    toml.write_text(FIRST_RUN)
    cache = Path(tempfile.mkdtemp(prefix=f"cache-{tag}-", dir=tmp))
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-c", FIRST_CHILD, str(toml)], env=_env(tree, cache),
                       cwd=tmp, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode:
        raise SystemExit(f"the first-run child failed ({p.returncode}):\n{p.stderr[-3000:]}")
    kernels = json.loads(p.stderr.strip().splitlines()[-1])
    return {"wall": wall, "cpu": (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime),
            "compile": sum(kernels.values()), "kernels": kernels}


def first_reproduce(tmp: Path, tree: Path | None, tag: str) -> dict:
    """The first ``reproduce --quick`` on an empty cache: wall, CPU, its stated compile time."""
    cache = Path(tempfile.mkdtemp(prefix=f"cache-rq-{tag}-", dir=tmp))
    out = Path(tempfile.mkdtemp(prefix=f"rq-{tag}-", dir=tmp))
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "hertzchain", "reproduce", "--quick", "--out",
                        str(out), "--no-progress"], env=_env(tree, cache), cwd=tmp,
                       capture_output=True, text=True)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode:
        raise SystemExit(f"reproduce failed ({p.returncode}):\n{p.stderr[-3000:]}")
    m = re.search(r"numba spent (\d+(?:\.\d+)?) s of CPU compiling", p.stdout + p.stderr)
    return {"wall": wall, "cpu": (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime),
            "compile": float(m.group(1)) if m else float("nan")}


def _verdict(value: float, target: float) -> str:
    return "meets" if value <= target else "misses"


def first_runs(a, load0: float) -> tuple[str, str]:
    """The first-run measurements (interleaved with the baseline tree's); table, notes."""
    trees = [("this code", None)] + ([("baseline", a.baseline_tree)] if a.baseline_tree
                                     else [])
    res = {name: [] for name, _ in trees}
    rq = {name: [] for name, _ in trees}
    with tempfile.TemporaryDirectory(prefix="hc-first-") as tmp:
        for k in range(a.rounds):
            for name, tree in (trees if k % 2 == 0 else trees[::-1]):
                res[name].append(first_run(Path(tmp), tree, f"{name[:4]}{k}"))
                if a.reproduce:
                    rq[name].append(first_reproduce(Path(tmp), tree, f"{name[:4]}{k}"))
    load1 = os.getloadavg()[0]
    # on a loaded machine the wall time includes waiting for a core: judge the CPU time
    basis = "wall" if max(load0, load1) <= 1.5 else "cpu"
    med = {name: {q: statistics.median(r[q] for r in runs) for q in ("wall", "cpu", "compile")}
           for name, runs in res.items()}
    print(f"CPU: {cpu_name()}; load average {load0:.1f} → {load1:.1f}; {a.rounds} round(s)"
          + (", interleaved with the baseline" if a.baseline_tree else ""))
    rows = []
    for name, m in med.items():
        top = sorted(res[name][0]["kernels"].items(), key=lambda kv: -kv[1])[:3]
        print(f"first run, {name}: wall {m['wall']:.1f} s, CPU {m['cpu']:.1f} s, numba "
              f"compiling {m['compile']:.1f} s CPU; largest: "
              + ", ".join(f"{n.rsplit('.', 1)[-1]} {t:.1f} s" for n, t in top))
        rows.append([f"first `hertzchain run`, 500 grains ({name})", f"{m['wall']:.1f}",
                     f"{m['cpu']:.1f}", f"{m['compile']:.1f}",
                     f"≤ {TARGET_FIRST_RUN_WALL:.0f} s wall: "
                     f"{_verdict(m[basis], TARGET_FIRST_RUN_WALL)} it"
                     + (" (by its CPU time: loaded machine)" if basis == "cpu" else "")])
    for name, runs in rq.items():
        if not runs:
            continue
        m = {q: statistics.median(r[q] for r in runs) for q in ("wall", "cpu", "compile")}
        print(f"first reproduce --quick, {name}: wall {m['wall']:.0f} s, CPU {m['cpu']:.0f} s, "
              f"numba spent {m['compile']:.0f} s compiling (stated)")
        rows.append([f"first `reproduce --quick` ({name})", f"{m['wall']:.0f}",
                     f"{m['cpu']:.0f}", f"{m['compile']:.0f}",
                     f"≤ {TARGET_REPRODUCE_COMPILE:.0f} s compiling: "
                     f"{_verdict(m['compile'], TARGET_REPRODUCE_COMPILE)} it"])
    if a.baseline_tree:
        b, t = med["baseline"], med["this code"]
        print(f"this code / baseline: wall {t['wall'] / b['wall']:.2f}, CPU "
              f"{t['cpu'] / b['cpu']:.2f}, compile CPU {t['compile'] / b['compile']:.2f}")
    for what, key in (("wall", "wall"), ("CPU", "cpu")):
        v = med["this code"][key]
        print(f"target (first run <= {TARGET_FIRST_RUN_WALL:.0f} s wall), {what} {v:.1f} s: "
              f"{_verdict(v, TARGET_FIRST_RUN_WALL)} it")
    if load1 > 1.5:
        print(f"(load average {load1:.1f} on {os.cpu_count()} cores: wall times include "
              "waiting for the CPU; an idle machine's wall time is about the CPU time)")
    table = markdown_table(["first run, empty kernel cache", "wall s", "CPU s",
                            "numba compiling, CPU s", "target"], rows)
    notes = (f"Medians over {a.rounds} round(s), each a fresh process on an empty cache"
             + (f", alternating with the baseline code (DIR: a checkout of other code, "
                f"here {a.baseline_tree.name})" if a.baseline_tree else "")
             + ".  Compiling: numba's outermost compile events (CPU) inside the run; for "
             "reproduce, the CPU seconds it states (summed over its worker processes).")
    return table, notes


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=1, help="cold processes (>= 1; default 1)")
    ap.add_argument("--baseline-tree", type=Path, default=None,
                    help="a checkout of other code, timed in alternation with this one")
    ap.add_argument("--reproduce", action="store_true",
                    help="also the first `hertzchain reproduce --quick` (about a minute each)")
    ap.add_argument("--first-run-only", action="store_true",
                    help="only the first-run measurements (not the per-family table)")
    ap.add_argument("--write-docs", action="store_true",
                    help="write the tables into docs/benchmarks.md (sections 'compile' and "
                         "'first-run')")
    a = ap.parse_args(argv)
    if a.rounds < 1:
        ap.error(f"--rounds must be >= 1, got {a.rounds}")
    if a.baseline_tree is not None and not (a.baseline_tree / "discrete").is_dir():
        ap.error(f"--baseline-tree must be a checkout of this project (no discrete/ in "
                 f"{a.baseline_tree})")
    load0 = os.getloadavg()[0]
    first_table, first_notes = first_runs(a, load0)
    print(first_table)
    if a.write_docs:
        argv, sys.argv = sys.argv, [  # the command as written down: no local paths
            {"--baseline-tree": "DIR"}.get(prev, x)
            for prev, x in zip([None, *sys.argv[:-1]], sys.argv, strict=True)]
        try:
            body = section(first_table, load=(load0, os.getloadavg()[0]), notes=first_notes)
        finally:
            sys.argv = argv
        write_section("first-run", body)
    if a.first_run_only:
        return 0
    load0 = os.getloadavg()[0]
    runs = []
    with tempfile.TemporaryDirectory(prefix="hc-compile-") as tmp:
        for k in range(a.rounds):
            cache = Path(tmp) / f"cache{k}"
            runs.append(one_process(Path(tmp), cache))
            if k == 0 and one_process(Path(tmp), cache):
                raise SystemExit("FAIL: a warm process compiled kernels again")
    load1 = os.getloadavg()[0]
    rows = []
    for label, _ in CASES:
        for fam, (what, expected) in KERNEL_FAMILIES.items():
            got = [r[(label, fam)] for r in runs if (label, fam) in r]
            if not got:
                continue
            rows.append([label, f"{what.removeprefix('the ').removesuffix(chr(39) + 's')}",
                         f"{statistics.median(g[1] for g in got):.1f}",
                         f"{statistics.median(g[0] for g in got):.1f}",
                         f"{expected:.0f}"])
    table = markdown_table(["scenario (in this order)", "kernels", "compile CPU s",
                            "compile wall s", "announced as about (s)"], rows)
    notes = (f"Medians over {a.rounds} cold process{'es' if a.rounds > 1 else ''}; "
             "the second scenario compiles only what the first did not (the same contact "
             "law: no discrete kernel again).  A warm process compiled nothing.")
    print(table)
    print(notes)
    if a.write_docs:
        write_section("compile", section(table, load=(load0, load1), notes=notes))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
