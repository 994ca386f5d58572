"""hertzchain beside LAMMPS on the same problem: agreement, throughput, time to solution.

The problem: N paper grains (d = 5 mm, stainless steel E = 193 GPa, ν = 0.30,
ρ = 7900 kg/m³), δ0 = 0, both ends free, grain 0 given v0 = 1 m/s, run until the
leading velocity peak passes grain 0.75 N.  Both codes integrate Eq. 2 with velocity
Verlet at the same dt.  LAMMPS gets it as ``pair_style gran/hertz/history`` with
``kn = k/√(d/4)`` (its Hertzian force is kn δ √(δ R_eff), R_eff = d/4, so
F = k δ^{3/2} with the Hertz constant k = E√d/(3(1-ν²)) of
:func:`theory.hertz_constant`), no damping, no friction, and ``fix nve`` (no rotation:
there are no tangential forces).  This script writes the LAMMPS data file and input
(never LAMMPS code: the program is the user's ``lmp``), runs ``lmp`` when it is on the
PATH, and otherwise says that it skipped.

What it prints, per N:

* agreement: v̄max/v0 at grain N/2 from both codes at the same dt (LAMMPS: the grain's
  velocity printed every step of a validation run, whose maximum is taken here) and the
  wave speed (grains per second between grains 0.25 N and 0.5 N from the times of
  those maxima);
* throughput: grain-updates per second of the integration loop (LAMMPS: N × steps /
  its "Loop time"; hertzchain: N × steps / the run's wall time in a warm process, the
  kernels loaded — every grain, though hertzchain integrates only the active window);
* time to solution at the same accuracy, start-up included: the whole ``lmp`` process
  at the dt hertzchain's ``rtol`` run chose (velocity Verlet: same method and dt, so the
  same error), and the whole ``hertzchain run --rtol`` process (neither writes a
  result file).

For long LAMMPS runs (``--lammps-budget`` seconds exceeded by the estimate) the LAMMPS
time to solution is extrapolated from a timed fraction of the steps, and marked so.

    python benchmarks/lammps.py                 # N = 2000 and 20000
    python benchmarks/lammps.py --grains 2000 --keep /tmp/lmp
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _machine import cpu_name  # (before this folder leaves sys.path, if it does)

D = 5e-3
V0 = 1.0


def material():
    import theory

    m = theory.PAPER_MATERIAL
    return m, float(theory.hertz_constant(D, m)), float(theory.grain_mass(D, m.density))


def write_lammps(folder: Path, n: int, dt: float, steps: int, *, watch: int | None) -> Path:
    """Write ``chain.data`` and ``in.chain`` for N grains; return the input's path.

    ``watch``: print that grain's x-velocity every step (validation run), else silent.
    """
    mat, k, _ = material()
    kn = k / math.sqrt(D / 4.0)
    lines = ["hertzchain benchmark: 1-D chain of touching spheres (benchmarks/lammps.py)", "",
             f"{n} atoms", "1 atom types", "",
             f"{-2 * D:.10g} {(n + 2) * D:.10g} xlo xhi",
             f"{-2 * D:.10g} {2 * D:.10g} ylo yhi",
             f"{-2 * D:.10g} {2 * D:.10g} zlo zhi", "", "Atoms # sphere", ""]
    lines += [f"{i + 1} 1 {D:.10g} {mat.density:.10g} {i * D:.17g} 0 0" for i in range(n)]
    lines += ["", "Velocities", ""]
    lines += [f"{i + 1} {V0 if i == 0 else 0.0:.10g} 0 0 0 0 0" for i in range(n)]
    (folder / "chain.data").write_text("\n".join(lines) + "\n")
    out = []
    if watch is not None:  # grains N/4 and N/2 (``watch``), every step
        out = [f"variable va equal vx[{watch // 2 + 1}]", f"variable vw equal vx[{watch + 1}]",
               f"fix pr all print 1 \"${{va}} ${{vw}}\" file {folder / 'vwatch.txt'} "
               "screen no"]
    text = "\n".join([
        "units si", "atom_style sphere", "dimension 3", "boundary f f f",
        "atom_modify map array", "comm_modify vel yes", "newton off",
        f"read_data {folder / 'chain.data'}",
        f"pair_style gran/hertz/history {kn:.17g} NULL 0 0 0 0",
        "pair_coeff * *", f"neighbor {0.1 * D:.10g} bin",
        "neigh_modify delay 0 every 1 check yes",
        "fix 1 all nve", f"timestep {dt:.17g}", "thermo 0", *out, f"run {steps}", ""])
    path = folder / "in.chain"
    path.write_text(text)
    return path


def run_lmp(inp: Path) -> dict:
    """Run ``lmp -in inp`` on one core; whole-process time and the loop time, s."""
    t0 = time.perf_counter()
    res = subprocess.run(["lmp", "-in", str(inp), "-log", str(inp.parent / "log.lammps")],
                         capture_output=True, text=True, env={**os.environ,
                                                              "OMP_NUM_THREADS": "1"})
    wall = time.perf_counter() - t0
    if res.returncode != 0:
        raise RuntimeError(f"lmp failed:\n{res.stdout[-2000:]}\n{res.stderr[-2000:]}")
    m = re.search(r"Loop time of ([0-9.eE+-]+) on", res.stdout)
    return {"process": wall, "loop": float(m.group(1)) if m else math.nan}


def _scenario_toml(n: int, **run) -> str:
    return "\n".join(["name = \"lammps-side-by-side\"", "[chain]", "right_wall = \"free\"",
                      "[[chain.sections]]", f"n = {n}", "[initial]", "kind = \"impact\"",
                      f"v0 = {V0}", "[run]", f"until_front_at = {int(0.75 * n)}",
                      *[f"{k} = {json.dumps(v)}" for k, v in run.items()],
                      "[record]", "running_max = true", ""])


def hertzchain_run(n: int, folder: Path, **run) -> dict:
    """A whole ``hertzchain run`` process on the problem: its summary and process time.

    No output file: like the LAMMPS run (``thermo 0``, no dump), the process computes
    the answer and prints its summary; start-up (imports, numba's first load of the
    cached kernels) included.
    """
    path = folder / f"hc{n}.toml"
    path.write_text(_scenario_toml(n, **run))
    exe = Path(sys.executable).with_name("hertzchain")
    t0 = time.perf_counter()
    res = subprocess.run([str(exe), "run", str(path), "--json", "--threads", "1"],
                         capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if res.returncode != 0:
        raise RuntimeError(res.stderr[-2000:])
    return {"summary": json.loads(res.stdout.strip().splitlines()[-1]), "process": wall}


def hertzchain_warm(n: int, **run) -> dict:
    """The same run in this (warm) process: summary and v̄max/v0 per grain.

    Its ``wall_time`` is the run alone (kernels loaded): the throughput.
    """
    import tomllib

    from hertzchain.runner import run_simulation
    from hertzchain.scenario import parse_scenario

    scenario = parse_scenario(tomllib.loads(_scenario_toml(n, **run)))
    summary, sim = run_simulation(scenario, threads=1)
    return {"summary": summary, "vmax": np.asarray(sim.record.vmax)}


def arrival_grid(n: int, dt: float):
    """hertzchain's v of grains N/4 and N/2 per step up to the leading peak at N/2.

    For the wave speed: the times of their velocity maxima (peak_time, cubic Hermite).
    """
    import discrete
    from discrete.interpolation import peak_time

    chain = discrete.Chain.from_sections([discrete.Section(n, D, material()[0])])
    init = discrete.initial.impact(chain, V0)
    g = [n // 4, n // 2]
    sim = init.simulation(dt=dt, record=discrete.Recording(series_grains=g))
    sim.run(until=discrete.WaveAt(n // 2), max_steps=10**9, progress=False)
    arr = sim.record.arrays()
    t, ser = arr["series_t"], arr["series"]
    times = []
    for q in range(2):  # v of grain g[q]; its derivative from the series' finite difference
        v = ser[:, q, 1]
        times.append(peak_time(t, v, np.gradient(v, t))[0])
    return (g[1] - g[0]) / (times[1] - times[0])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--grains", type=int, nargs="+", default=[2000, 20000])
    p.add_argument("--rtol", type=float, default=1e-4)
    p.add_argument("--lammps-budget", type=float, default=60.0,
                   help="seconds a LAMMPS run may take before it is extrapolated")
    p.add_argument("--keep", default=None, help="keep the LAMMPS files in this folder")
    p.add_argument("--repeats", type=int, default=3,
                   help="hertzchain runs per row up to 5000 grains (best is shown)")
    a = p.parse_args()
    print(f"# {cpu_name()} (both codes on one core), load average "
          f"{os.getloadavg()[0]:.2f}")
    have_lmp = shutil.which("lmp") is not None
    if not have_lmp:
        print("# SKIPPED LAMMPS: no `lmp` on the PATH (Debian: apt-get install lammps); "
              "hertzchain's side only")
    else:
        ver = subprocess.run(["lmp", "-h"], capture_output=True, text=True).stdout
        m = re.search(r"Large-scale Atomic/Molecular Massively Parallel Simulator - (.*)",
                      ver)
        print(f"# LAMMPS: {m.group(1).strip() if m else 'version unknown'}")
    folder = Path(a.keep) if a.keep else Path(tempfile.mkdtemp(prefix="hc-lammps-"))
    folder.mkdir(parents=True, exist_ok=True)
    hertzchain_warm(200)  # imports done, kernels loaded
    for n in a.grains:
        reps = a.repeats if n <= 5000 else 1  # best of the repeats (a shared machine)
        hc_def = min((hertzchain_run(n, folder) for _ in range(reps)),
                     key=lambda r: r["process"])
        dt0, steps0 = hc_def["summary"]["dt"], hc_def["summary"]["steps"]
        hc = min((hertzchain_run(n, folder, rtol=a.rtol) for _ in range(reps)),
                 key=lambda r: r["process"])
        dt1, steps1 = hc["summary"]["dt"], hc["summary"]["steps"]
        print(f"\n## N = {n}: default dt {dt0:.4g} s ({steps0} steps); rtol {a.rtol:g}: "
              f"dt {dt1:.4g} s ({steps1} steps, estimate "
              f"{hc['summary']['rtol_estimate']:.2e})")
        # run time and throughput of a warm process (up to 5,000 grains; beyond, the
        # process's own summary, whose start-up share is small)
        if n <= 5000:
            w_def = min((hertzchain_warm(n) for _ in range(reps)),
                        key=lambda r: r["summary"]["wall_time"])
            w_rtol = min((hertzchain_warm(n, rtol=a.rtol) for _ in range(reps)),
                         key=lambda r: r["summary"]["wall_time"])
            vm_hc = float(w_def["vmax"][n // 2])
            print(f"hertzchain v̄max/v0 at grain {n // 2}: {vm_hc:.7f} (default dt), "
                  f"{float(w_rtol['vmax'][n // 2]):.7f} (rtol)")
            run_def, run_rtol = (w_def["summary"]["wall_time"],
                                 w_rtol["summary"]["wall_time"])
        else:
            run_def, run_rtol = hc_def["summary"]["wall_time"], hc["summary"]["wall_time"]
        rows = [("hertzchain, default dt", hc_def["process"], run_def, n * steps0 / run_def,
                 ""),
                (f"hertzchain, rtol {a.rtol:g}", hc["process"], run_rtol,
                 n * steps1 / run_rtol, "")]
        if have_lmp:
            # agreement: the validation run at the default dt, to the peak past grain N/2
            if n <= 5000:  # (vm_hc: the warm default run above)
                half = int(steps0 * 0.5 / 0.75) + 2000
                inp = write_lammps(folder, n, dt0, half, watch=n // 2)
                run_lmp(inp)
                vv = np.loadtxt(folder / "vwatch.txt", comments="#")
                vw = vv[:, 1]
                print(f"LAMMPS     v̄max/v0 at grain {n // 2}: {float(np.max(vw)):.7f} "
                      f"(default dt); difference {abs(float(np.max(vw)) - vm_hc):.2e}")
                # wave speed between grains N/4 and N/2 from the steps of the peaks
                i1, i2 = int(np.argmax(vv[:, 0])), int(np.argmax(vw))
                speed_l = (n // 2 - (n // 2) // 2) * D / ((i2 - i1) * dt0)
                speed_hc = arrival_grid(n, dt0) * D
                print(f"wave speed between grains {n // 4} and {n // 2}: LAMMPS "
                      f"{speed_l:.3f} m/s (peaks at steps), hertzchain {speed_hc:.3f} m/s "
                      f"(Hermite peak times); relative difference "
                      f"{abs(speed_l / speed_hc - 1):.1e}")
            # throughput and time to solution at the rtol dt (same method and dt)
            probe = max(1000, min(steps1, 20000))
            t_probe = run_lmp(write_lammps(folder, n, dt1, probe, watch=None))
            rate = n * probe / t_probe["loop"]
            est = t_probe["process"] - t_probe["loop"] + n * steps1 / rate
            if est <= a.lammps_budget:
                full = run_lmp(write_lammps(folder, n, dt1, steps1, watch=None))
                rows.append(("LAMMPS, same dt as rtol", full["process"], full["loop"],
                             n * steps1 / full["loop"], ""))
            else:
                rows.append(("LAMMPS, same dt as rtol", est, est - (t_probe["process"]
                                                                    - t_probe["loop"]),
                             rate, f"extrapolated from {probe} steps"))
        print(f"{'':>26} {'process s':>10} {'run s':>9} {'grain-updates/s':>16}")
        for name, proc, run, rate, note in rows:
            print(f"{name:>26} {proc:>10.3f} {run:>9.3f} {rate:>16.3e} {note}")
        if have_lmp:
            lmp_proc = rows[-1][1]
            print(f"time to solution at equal accuracy (start-up included): LAMMPS / "
                  f"hertzchain = {lmp_proc / hc['process']:.1f}")


if __name__ == "__main__":
    main()
