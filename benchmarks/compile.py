"""First-run compilation of the kernels: what a cold numba cache costs, per family.

A fresh interpreter with an empty ``NUMBA_CACHE_DIR`` runs two small scenarios through
``hertzchain run`` — a precompressed two-section chain with the continuum's Eq. 4, then
the same at δ0 = 0 with Eq. 7 — and sums, per kernel family
(:data:`theory.jitcache.KERNEL_FAMILIES`) and scenario, the wall and CPU time of numba's
outermost ``"numba:compile"`` events (fired only on a cache miss).  The last column is
the duration the run announces before compiling (``KERNEL_FAMILIES``); a second,
warm process must compile nothing.

    python benchmarks/compile.py                 # 1 round
    python benchmarks/compile.py --rounds 3      # medians over 3 cold processes
    python benchmarks/compile.py --write-docs    # also into docs/benchmarks.md
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

from _docs import markdown_table, section, write_section

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

CASES = (("precompressed, Eq. 4", dict(name="eq4", delta0=1e-3, v=0.05, eq="eq4")),
         ("δ0 = 0, Eq. 7", dict(name="eq7", delta0=0.0, v=0.5, eq="eq7")))

CHILD = textwrap.dedent("""
    import json, sys, threading, time
    from numba.core import event
    from theory.jitcache import KERNEL_FAMILIES
    from hertzchain.cli import main

    totals, local = {}, threading.local()

    class Timer(event.Listener):
        def on_start(self, ev):
            depth = getattr(local, "depth", 0)
            if depth == 0:
                mod = ev.data["dispatcher"].py_func.__module__.split(".")[0]
                local.start = (mod, time.perf_counter(), time.process_time())
            local.depth = depth + 1

        def on_end(self, ev):
            local.depth -= 1
            if local.depth == 0:
                mod, wall, cpu = local.start
                if mod in KERNEL_FAMILIES:
                    w, c = totals.get((case, mod), (0.0, 0.0))
                    totals[(case, mod)] = (w + time.perf_counter() - wall,
                                           c + time.process_time() - cpu)

    event.register("numba:compile", Timer())
    for case, toml in json.loads(sys.argv[1]):
        if main(["run", toml, "--json"]) != 0:
            raise SystemExit(f"hertzchain run {toml} failed")
    print(json.dumps([[c, m, w, p] for (c, m), (w, p) in totals.items()]),
          file=sys.stderr)
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


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=1, help="cold processes (>= 1; default 1)")
    ap.add_argument("--write-docs", action="store_true",
                    help="write the table into docs/benchmarks.md (section 'compile')")
    a = ap.parse_args(argv)
    if a.rounds < 1:
        ap.error(f"--rounds must be >= 1, got {a.rounds}")
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
