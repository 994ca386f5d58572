"""Time to solution at a stated accuracy: the default dt against ``rtol``.

The problem: an impact (v0 = 1 m/s on grain 0) on N paper grains (d = 5 mm, steel,
ν = 0.30), δ0 = 0, both ends free, run until the leading velocity peak passes grain
0.75 N — the scenario ``hertzchain run`` would run, through the same path
(:func:`hertzchain.runner.run_simulation`: energy grid, running maxima, summary).  The
recorded quantity is v̄max/v0, every grain's running maximum of v over v0, on the
settled part of the chain (grains 0.1 N .. 0.7 N): the refined maximum
(``record.vmax_refined``, between the steps; what rtol bounds) where the code records
it, else the largest sample (``record.vmax``; a baseline tree from before the refined
maxima); both errors are printed ("err N/2" and "max err" of the run's refined maxima,
"sampled" the max error of its samples).  "Converged" is the refined maxima of the same
run with Blanes-Moan 4 at half the default dt (measured on a 150-grain impact: ~1e-9
off; the target is 1e-4).  An rtol run of this one-section chain records no energy
grid: its summary's front speed (the one number it read from the grid) comes from the
refined peak times (``hertzchain.measure.front_speed_from_maxima``).  "rows" is the grid's row
count (0: none) and "front dev" the relative difference of the run's front speed from
the converged run's (the grid estimator, :func:`converged`).  Each
row is timed by the run's own summary (``wall_time``: chain, initial state, the rtol
probe when there is one, integration, summary), best of ``--repeats`` interleaved
repeats; the ratios are measured in the same run of this script.  The CPU time of the
same call (``cpu s``, best of the repeats) is printed beside it: on a shared machine it
is the steadier figure.

    python benchmarks/rtol.py                       # N = 2000 and 5000
    python benchmarks/rtol.py --grains 2000 --baseline-tree /tmp/base
    python benchmarks/rtol.py --grains 2000 --interface a   # + the energy ratios' cost

``--interface POINT`` also prices the phase-averaged kinetic/potential split of the
energy ratios (docs/physics.md §6) on the same impact with an interface at N/2 (the
right half at the paper's POINT): the run with the grid rows the split needs
(:func:`hertzchain.runner.split_row_spacing`) against the same run with the rows every
``GRID_ROWS_PER_GRAIN`` transits (the rule before; ``record.energy_every`` set to
it), default dt and rtol, CPU s best of the repeats; and the summary's ratio step, the
windowed mean (:func:`discrete.diagnostics.phase_averaged_ratios`) against one row
(:func:`discrete.diagnostics.energy_ratios_from_grid`) on the run's grid.  Runs
without an interface record no grid for the split and pay nothing.

``--baseline-tree DIR`` also times the default run of another checkout (``git archive``
of an older commit) in a fresh process; the
speed-ups are then against it, and "vs def" against this tree's default run.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from _machine import cpu_name  # (before this folder leaves sys.path, if it does)

SPEEDUP_TARGET = 5.0
"""Run time of the default step over that of ``rtol`` (the method chosen), same run."""

ERROR_WITHIN = 0.4
"""The achieved error of the rtol run should lie in [ERROR_WITHIN, 1] × rtol (~2x)."""


def scenario(n: int, **run):
    from hertzchain.scenario import parse_scenario

    return parse_scenario({"name": f"impact{n}", "chain": {"sections": [{"n": n}]},
                           "initial": {"kind": "impact", "v0": 1.0},
                           "run": {"until_front_at": int(0.75 * n), **run},
                           "record": {"running_max": True}})


def measure(n: int, **run) -> dict:
    """One run: the summary's wall time, dt, steps and v̄max/v0 per grain."""
    from hertzchain.runner import run_simulation

    cpu = time.process_time()
    summary, sim = run_simulation(scenario(n, **run))
    cpu = time.process_time() - cpu
    refined = getattr(sim.record, "vmax_refined", None)  # (None: a tree without refined maxima)
    return {"wall_time": summary["wall_time"], "cpu": cpu, "dt": summary["dt"],
            "steps": summary["steps"], "front_speed": summary["front_speed_tr"],
            "rows": len(sim.record.energy_t),
            "integrator": sim.integrator, "estimate": summary.get("rtol_estimate"),
            "maxima": getattr(sim.time_step, "maxima", None),
            "vmax": np.asarray(sim.record.vmax, float).tolist(),
            "vmax_refined": None if refined is None else np.asarray(refined, float).tolist()}


def converged(n: int, dt: float) -> tuple[list, float]:
    """Refined v̄max/v0 and front speed (m/s) of the scenario, Blanes-Moan 4 at step ``dt``.

    The front speed is the summary's estimator on an energy grid with rows every
    ``GRID_ROWS_PER_GRAIN`` transits, coarsened by 1 (N <= 2,000) or 2 (measured on the
    2,000-grain impact: 8e-8 apart; by 8, as the default run's grid at 5,000 grains,
    1.3e-4).
    """
    from discrete import Recording, WaveAt
    from hertzchain.runner import (
        GRID_ROWS_PER_GRAIN,
        _wave_speed_estimate,
        build_simulation,
        summarise,
    )

    chain, init, _ = build_simulation(scenario(n), energy_grid=False)
    d = float(np.mean(init.chain.diameter))
    every = max(1, int(GRID_ROWS_PER_GRAIN * d / (_wave_speed_estimate(chain, init.v) * dt)))
    sim = init.simulation(dt=dt, integrator="blanes_moan4",
                          record=Recording(maxima=True, refined_maxima=True,
                                           energy_every=every,
                                           energy_coarsen=1 if n <= 2000 else 2))
    sim.run(until=WaveAt(int(0.75 * n)), progress=False)
    front = summarise(chain, sim)["front_speed_tr"]
    return np.asarray(sim.record.vmax_refined, float).tolist(), front


def interface_cost(n: int, point: str, rtol: float, repeats: int) -> None:
    """Print the energy ratios' extra cost on a two-section impact (``--interface``)."""
    import theory
    from discrete import diagnostics as D
    from hertzchain.runner import (
        GRID_ROWS_PER_GRAIN,
        _wave_speed_estimate,
        build_simulation,
        run_simulation,
        split_row_spacing,
    )
    from hertzchain.scenario import parse_scenario

    ar, ak = theory.PAPER_POINTS[point]

    def sc(record=None, **run):
        return parse_scenario({
            "chain": {"sections": [{"n": n // 2},
                                   {"n": n - n // 2, "alpha_rho": ar, "alpha_kn": ak}]},
            "initial": {"kind": "impact", "v0": 1.0},
            "run": {"until_front_at": int(0.9 * n), **run}, "record": record or {}})

    chain, init, _ = build_simulation(sc(), energy_grid=False)
    speed, d = _wave_speed_estimate(chain, init.v), float(np.mean(chain.diameter))
    print(f"\n## energy ratios: impact, N = {n}, interface at N/2, point {point} "
          f"(rows every {split_row_spacing(chain):.3f} transits for the split, "
          f"{GRID_ROWS_PER_GRAIN} before)")
    print(f"{'run':>14} {'rows':>6} {'cpu s':>7} {'old rows':>8} {'cpu s':>7} {'x':>6} "
          f"{'window ms':>9} {'one row ms':>10} {'split est':>9}")
    for name, run in (("default", {}), (f"rtol {rtol:g}", {"rtol": rtol, "integrator": "auto"})):
        new, old = [], []
        for _ in range(repeats):
            c = time.process_time()
            s, sim = run_simulation(sc(**run), save=False)
            new.append(time.process_time() - c)
            every_old = max(1, int(GRID_ROWS_PER_GRAIN * d / (speed * s["dt"])))
            c = time.process_time()
            _, sim_old = run_simulation(sc({"energy_every": every_old}, **run), save=False)
            old.append(time.process_time() - c)
        a = sim.record.arrays()
        t, ek, ep = a["energy_t"], a["energy_kinetic"], a["energy_potential"]
        coarsen = sim.record.energy_coarsen
        iface = (n // 2) // coarsen
        sec = chain.section[::coarsen][: ek.shape[1]]
        e = ek + ep
        i_in = D.incident_time_index(e, iface)
        i_out = next(i for f in (1e-6, 1e-5, 1e-4, 1e-3)
                     if (i := D.separated_time_index(e, iface, fraction=f)) is not None)
        tw = time.process_time()
        for _ in range(5):
            D.phase_averaged_ratios(t, ek, ep, sec, i_in, i_out, coarsen=coarsen)
        tw = (time.process_time() - tw) / 5
        t1 = time.process_time()
        for _ in range(5):
            D.energy_ratios_from_grid(ek, ep, sec, i_in, i_out)
        t1 = (time.process_time() - t1) / 5
        print(f"{name:>14} {len(t):>6} {min(new):>7.3f} {len(sim_old.record.energy_t):>8} "
              f"{min(old):>7.3f} {min(new) / min(old):>5.2f}× {tw * 1e3:>9.2f} "
              f"{t1 * 1e3:>10.2f} {s['split_estimate']:>9.1e}")


def _tree_default(tree: str, n: int) -> dict:
    """The default run of ``tree``'s packages in a fresh process (this file's --child)."""
    env = dict(os.environ)
    env["PYTHONPATH"] = str(Path(tree).resolve()) + os.pathsep + env.get("PYTHONPATH", "")
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", str(n)]
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True,
                         cwd=tree).stdout
    return json.loads(out.strip().splitlines()[-1])


def errors(vmax, ref, n: int) -> tuple[float, float]:
    """(|v̄max/v0 - converged| at grain N/2, max over grains 0.1 N .. 0.7 N)."""
    lo, hi = int(0.1 * n), int(0.7 * n)
    d = np.abs(np.asarray(vmax)[lo:hi] - np.asarray(ref)[lo:hi])
    return float(abs(vmax[n // 2] - ref[n // 2])), float(np.max(d))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--grains", type=int, nargs="+", default=[2000, 5000])
    p.add_argument("--rtol", type=float, default=1e-4)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--baseline-tree", metavar="DIR", default=None)
    p.add_argument("--json", action="store_true")
    p.add_argument("--interface", metavar="POINT", default=None,
                   help="also price the energy ratios' split on an interface at N/2 "
                        "(a paper point: a, b, c, d, M, N, P, Q)")
    p.add_argument("--child", type=int, default=None, help=argparse.SUPPRESS)
    a = p.parse_args()
    if a.child is not None:  # warm first (imports, kernels loaded), as the rows here
        measure(max(200, a.child // 10))
        print(json.dumps(measure(a.child)))
        return
    from discrete.timestep import default_dt  # noqa: F401 (warm imports, kernels)

    print(f"# {cpu_name()}, load average {os.getloadavg()[0]:.2f}; "
          f"impact on N grains, delta0 = 0, until grain 0.75 N; rtol = {a.rtol:g}")
    results, targets = [], []
    for n in a.grains:
        measure(max(200, n // 10))  # warm: kernels loaded, imports done
        measure(max(200, n // 10), rtol=a.rtol, integrator="auto")
        ref_dt = measure(n)["dt"] / 2
        ref, fs_ref = converged(n, ref_dt)
        rows = {"default": [], f"rtol {a.rtol:g}": [], f"rtol {a.rtol:g} auto": []}
        if a.baseline_tree:
            rows["baseline default"] = []
        for _ in range(a.repeats):
            rows["default"].append(measure(n))
            rows[f"rtol {a.rtol:g}"].append(measure(n, rtol=a.rtol))
            rows[f"rtol {a.rtol:g} auto"].append(measure(n, rtol=a.rtol, integrator="auto"))
            if a.baseline_tree:
                rows["baseline default"].append(_tree_default(a.baseline_tree, n))
        best = {k: {**min(v, key=lambda r: r["wall_time"]),
                    "cpu": min(r.get("cpu", math.nan) for r in v)} for k, v in rows.items()}
        base = best.get("baseline default", best["default"])["wall_time"]
        print(f"\n## N = {n} (converged: Blanes-Moan 4, dt = {ref_dt:.4g} s; v̄max/v0 at "
              f"N/2 = {ref[n // 2]:.7f}; front speed {fs_ref:.7g} m/s)")
        cpu_base = best.get("baseline default", best["default"]).get("cpu", math.nan)
        print(f"{'run':>18} {'integ.':>9} {'dt s':>10} {'steps':>8} {'wall s':>8} "
              f"{'speed-up':>8} {'cpu s':>7} {'cpu x':>6} {'err N/2':>9} {'max err':>9} "
              f"{'sampled':>9} {'estimate':>9} {'rows':>6} {'front dev':>9} {'vs def':>7}")
        own_base = best["default"]["wall_time"]  # this tree's default run, same run
        for k, r in best.items():
            own = r["vmax"] if r.get("vmax_refined") is None else r["vmax_refined"]
            e_mid, e_max = errors(own, ref, n)
            e_samp = errors(r["vmax"], ref, n)[1]
            est = r.get("estimate")
            est = "" if est is None or not np.isfinite(est) else f"{est:.2e}"
            cpu = r.get("cpu", math.nan)
            fs_dev = abs(r.get("front_speed", math.nan) / fs_ref - 1)
            print(f"{k:>18} {r['integrator']:>9} {r['dt']:>10.4g} {r['steps']:>8} "
                  f"{r['wall_time']:>8.3f} {base / r['wall_time']:>7.2f}× {cpu:>7.3f} "
                  f"{cpu_base / cpu:>5.2f}× {e_mid:>9.2e} {e_max:>9.2e} {e_samp:>9.2e} "
                  f"{est:>9} {r.get('rows', -1):>6} {fs_dev:>9.1e} "
                  f"{own_base / r['wall_time']:>6.2f}×")
            if k.endswith("auto") and "baseline" not in k:
                targets.append((n, k, own_base / r["wall_time"],
                                best["default"].get("cpu", math.nan) / cpu, e_max,
                                r.get("estimate"), r.get("maxima")))
            results.append({"grains": n, "run": k, "wall_time": r["wall_time"], "cpu": cpu,
                            "dt": r["dt"], "steps": r["steps"], "err_mid": e_mid,
                            "err_max": e_max, "err_sampled": e_samp,
                            "speedup": base / r["wall_time"],
                            "speedup_cpu": cpu_base / cpu, "rows": r.get("rows"),
                            "front_dev": fs_dev})
    print(f"\n## targets: rtol {a.rtol:g} (method chosen) against the default step, same "
          f"run: >= {SPEEDUP_TARGET:g}x less run time at >= 2,000 grains; achieved error "
          "(max err, against the converged run) <= rtol and within ~2x of it")
    for n, _, wall_x, cpu_x, err, est, maxima in targets:
        met = (wall_x >= SPEEDUP_TARGET or cpu_x >= SPEEDUP_TARGET) and n >= 2000
        within = ERROR_WITHIN * a.rtol <= err <= a.rtol
        print(f"  N = {n}: {wall_x:.2f}x wall, {cpu_x:.2f}x CPU (target {SPEEDUP_TARGET:g}x: "
              f"{'met' if met else 'NOT met'}); achieved error {err:.2e} = "
              f"{err / a.rtol:.2f} of the rtol asked (estimate {est:.2e}; {maxima or '?'} "
              f"maxima; target [{ERROR_WITHIN:g}, 1]: {'met' if within else 'NOT met'})")
    if a.interface:
        for n in a.grains:
            interface_cost(n, a.interface, a.rtol, a.repeats)
    if a.json:
        print(json.dumps(results))


if __name__ == "__main__":
    main()
