"""Start-up of a small run as a whole process (target: ≤ 0.8 s warm).

A warm ``hertzchain run`` of a 100-grain impact (kernels already in numba's cache) timed
as a whole process, beside the floors any numba program pays on the same machine in
the same run, interleaved round by round so that load changes hit every row alike:

* ``python``: the interpreter alone (``python -c pass``);
* ``numpy``: ``import numpy``;
* ``numba``: ``import numba``;
* ``numba + rocket-fft``: ``import numba; import rocket_fft`` — the imports every numba
  program of this environment pays: numba loads the rocket-fft extension through its
  entry points at the first dispatcher, and rocket-fft imports ``scipy.fft`` (with
  ``scipy.special`` and ``scipy._lib``);
* ``cached @njit``: ``import numba`` and the first call of one trivial ``@njit(cache=True)``
  function of an array, loaded from its cache — numba's target initialisation (its
  array registries, SciPy's BLAS for ``np.linalg`` through ``scipy.linalg``, the
  extension entry points above, ``numpy.ma`` for the array's type) is paid here;
* ``same, gc as ours``: the same with the collector as a ``hertzchain`` command sets it
  (the youngest generation's threshold raised to ``hertzchain.cli.GC_THRESHOLD0``,
  ``gc.freeze()`` at exit);
* ``hertzchain run``: ``hertzchain run impact100.toml --json --threads 1`` (parse, chain,
  kernels loaded from the cache, run, summary, JSON), or the scenario ``--scenario``
  names (e.g. the 2,000-grain chain of ``benchmarks/lammps.py``).

The remainder printed at the end is the run's time above each floor: what the solver's
own imports, kernel loads, rtol probe, run and summary cost beyond what any numba
program with one cached kernel costs.

Each row prints the median and the minimum over ``--repeats`` rounds of the wall time
(``time.perf_counter`` around the child) and of the child's CPU time (user + system,
``resource.getrusage(RUSAGE_CHILDREN)``); on a shared machine the CPU figure is the
steadier one.  ``PYTHONDONTWRITEBYTECODE`` is removed from the children's environment
(with it set, Python recompiles every module of ours at every start).

    python benchmarks/startup.py              # 9 rounds
    python benchmarks/startup.py --repeats 21
    python benchmarks/startup.py --scenario hc2000.toml   # another scenario, no docs
    python benchmarks/startup.py --write-docs # also into docs/benchmarks.md ('startup')
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _docs import markdown_table, section, write_section
from _machine import cpu_name
from _scenarios import impact_toml

from hertzchain.cli import GC_THRESHOLD0

SCENARIO = impact_toml(100, 80)

NJIT = """\
import numba


@numba.njit(cache=True)
def f(x):
    return x[0] + 1.0
"""

TARGET = 0.8
"""The target for a warm run of a small scenario, as a whole process, s."""


def timed(cmd: list[str], env: dict, cwd: str) -> tuple[float, float]:
    """Wall and CPU (user + system) time of one child process, s; raises if it fails."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, env=env, cwd=cwd, stdout=subprocess.DEVNULL,
                       stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr}")
    return wall, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=9, help="rounds (>= 1; default 9)")
    p.add_argument("--write-docs", action="store_true",
                   help="write the table into docs/benchmarks.md (section 'startup')")
    p.add_argument("--scenario", type=Path, default=None, metavar="TOML",
                   help="time this scenario instead of the 100-grain impact (not with "
                   "--write-docs)")
    a = p.parse_args(argv)
    if a.repeats < 1:
        p.error(f"--repeats must be >= 1, got {a.repeats}")
    if a.scenario is not None and a.write_docs:
        p.error("--write-docs documents the 100-grain impact: give no --scenario")
    if a.scenario is not None and not a.scenario.is_file():
        p.error(f"--scenario: no file {a.scenario}")
    exe = sys.executable
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    with tempfile.TemporaryDirectory(prefix="hc-startup-") as tmp:
        Path(tmp, "impact100.toml").write_text(SCENARIO)
        scenario = (str(a.scenario.resolve()) if a.scenario is not None
                    else "impact100.toml")
        Path(tmp, "njit1.py").write_text(NJIT)
        env_tmp = {**env, "PYTHONPATH": os.pathsep.join(
            [tmp] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))}
        rows = {
            "python": [exe, "-c", "pass"],
            "numpy": [exe, "-c", "import numpy"],
            "numba": [exe, "-c", "import numba"],
            "numba + rocket-fft": [exe, "-c", "import numba; import rocket_fft"],
            "cached @njit": [exe, "-c", "import numpy, njit1; njit1.f(numpy.zeros(2))"],
            "  same, gc as ours": [exe, "-c", f"import gc; gc.set_threshold({GC_THRESHOLD0}, "
                                   "*gc.get_threshold()[1:]); import numpy, njit1; "
                                   "njit1.f(numpy.zeros(2)); gc.freeze()"],
            "hertzchain run": [exe, "-m", "hertzchain", "run", scenario, "--json",
                               "--threads", "1"],
        }
        # warm-up: numba's caches of both programs, the .pyc files
        for cmd in rows.values():
            timed(cmd, env_tmp, tmp)
        times = {k: [] for k in rows}
        load0 = os.getloadavg()
        for _ in range(a.repeats):
            for k, cmd in rows.items():
                times[k].append(timed(cmd, env_tmp, tmp))
        load1 = os.getloadavg()
    print(f"CPU: {cpu_name()}; Python {platform.python_version()}; "
          f"load average {load0[0]:.1f} → {load1[0]:.1f}; {a.repeats} interleaved rounds; "
          f"hertzchain run of {a.scenario or 'a 100-grain impact'}")
    print(f"{'process':<18} {'wall median':>12} {'wall min':>9} {'CPU median':>11} "
          f"{'CPU min':>8}")
    med = {}
    for k, t in times.items():
        w = [x[0] for x in t]
        c = [x[1] for x in t]
        med[k] = (statistics.median(w), statistics.median(c))
        print(f"{k:<18} {med[k][0]:>11.3f}s {min(w):>8.3f}s {med[k][1]:>10.3f}s "
              f"{min(c):>7.3f}s")
    hc = med["hertzchain run"]
    for name, label in (("numba + rocket-fft", "the imports' floor (numba + rocket-fft)"),
                        ("  same, gc as ours", "the cached-@njit floor (same gc settings)")):
        floor = med[name]
        print(f"hertzchain run above {label}: remainder {hc[0] - floor[0]:+.3f} s wall, "
              f"{hc[1] - floor[1]:+.3f} s CPU; ratio {hc[0] / floor[0]:.2f} (wall), "
              f"{hc[1] / floor[1]:.2f} (CPU)")
    for what, value in (("CPU", hc[1]), ("wall", hc[0])):
        verdict = "meets" if value <= TARGET else "misses"
        print(f"target (warm run <= {TARGET} s as a whole process), median {what} "
              f"{value:.3f} s: {verdict} it")
    if load1[0] > 1.5:
        print(f"(load average {load1[0]:.1f} on {os.cpu_count()} cores: the wall times "
              "include waiting for the CPU; the CPU times are the processes' own)")
    table = markdown_table(
        ["process", "wall median s", "wall min s", "CPU median s", "CPU min s"],
        [[f"`{k.strip()}`" if k.strip() == "hertzchain run" else k.strip(),
          f"{med[k][0]:.3f}", f"{min(x[0] for x in t):.3f}", f"{med[k][1]:.3f}",
          f"{min(x[1] for x in t):.3f}"] for k, t in times.items()])
    print(table)
    if a.write_docs:
        floor = med["numba + rocket-fft"]
        notes = (f"{a.repeats} interleaved rounds after a warm-up.  `hertzchain run` is a "
                 "warm 100-grain impact as a whole process (`--threads 1`); the rows above "
                 "it are the floors any numba program pays (\"numba + rocket-fft\": the "
                 "imports; \"cached @njit\": one cached kernel of an array, which adds "
                 "numba's target initialisation; \"same, gc as ours\": with the collector "
                 "set as a `hertzchain` command sets it).  The run's remainder above the "
                 f"imports' floor: {hc[0] - floor[0]:+.3f} s wall, {hc[1] - floor[1]:+.3f} s "
                 "CPU (medians).  Target: "
                 f"≤ {TARGET} s.  Under load the CPU columns are the steadier ones.")
        write_section("startup", section(table, load=(load0[0], load1[0]), notes=notes))

if __name__ == "__main__":
    main()
