"""The time step of ``reproduce --full``'s Fig. 2, 6 and 7 runs: cost against the printed numbers.

Each candidate (integrator and ``dt_fraction``, or ``rtol``) is run through the one
run path (:func:`hertzchain.runner.run_simulation`, Fig. 7's points through
:func:`hertzchain.runner.run_scenario`) on the items' own scenarios (``fig2.scenario``,
``fig6.scenario`` with ``fig6.FULL``'s sizes, ``fig7.scenario``), the numbers the report
prints are computed with the items' own reductions, and each is compared with the
same number at the default step (velocity Verlet, default ``dt_fraction``: the baseline
"default dt", which ``--full`` ran before it chose its steps) and, for Fig. 2, with a
converged reference (Blanes–Moan 4, ``rtol = 1e-7``, refined maxima).

* Fig. 2: v̄max/v0 over the plateau (:func:`fig2._plateau` on the recorded maxima:
  the refined maxima ``record.vmax_refined`` where the run records them — an rtol run —
  else the sampled ``record.vmax``), the plateau's grains, its std and slope, for the
  paper's k_n and the two k_n variants at δ0/d = 1e-3, 20,000 grains.
* Fig. 6: every window of every α (V/c0^L, ξ_max, Eq. 5): the largest absolute change
  of V/c0^L and of V/V_Eq.5 - 1 (printed to 4 decimals / 0.01 %), and of ξ_max/ξ0^L.
* Fig. 7: the transmitted/reflected labels of the 408 points of ``fig7.FULL``: how
  many differ from the default dt's.

CPU time (``time.process_time``, one kernel thread) per candidate, summed over the
runs, with its ratio to the default dt measured in the same process: the machine
is shared, the CPU and load are printed.

Usage::

    python benchmarks/full_dt.py                 # all three studies
    python benchmarks/full_dt.py --fig2 --fig6   # some of them
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
from _machine import cpu_name

FIG2_CANDIDATES = {
    "default dt": {},
    "rtol 1e-5, auto": {"run.rtol": 1e-5, "run.integrator": "auto"},
    "rtol 1e-6, auto": {"run.rtol": 1e-6, "run.integrator": "auto"},
    "bm4 0.024": {"run.integrator": "blanes_moan4", "run.dt_fraction": 0.024},
}
FIG2_REFERENCE = {"run.rtol": 1e-7, "run.integrator": "blanes_moan4"}

FIG6_CANDIDATES = {
    "default dt": {},
    "verlet 0.001": {"run.dt_fraction": 0.001},
    "verlet 0.003": {"run.dt_fraction": 0.003},
    "verlet 0.004": {"run.dt_fraction": 0.004},
    "bm4 0.024": {"run.integrator": "blanes_moan4", "run.dt_fraction": 0.024},
    "bm4 0.048": {"run.integrator": "blanes_moan4", "run.dt_fraction": 0.048},
    "bm4 0.096": {"run.integrator": "blanes_moan4", "run.dt_fraction": 0.096},
}

FIG7_CANDIDATES = {
    "default dt": {},
    "bm4 0.048": {"integrator": "blanes_moan4", "dt_fraction": 0.048},
    "bm4 0.096": {"integrator": "blanes_moan4", "dt_fraction": 0.096},
}


def _run(sc):
    from hertzchain.runner import run_simulation

    c0 = time.process_time()
    summary, sim = run_simulation(sc, threads=1)
    return sim, time.process_time() - c0, summary


def _vmax(sim):
    r = sim.record
    return np.asarray(r.vmax_refined if r.vmax_refined is not None else r.vmax)


def fig2_study(candidates: dict) -> None:
    from hertzchain.reproduce import fig2

    n = fig2.FULL["n_grains"][1e-3]
    cases = ("hertz_nu030", *fig2.FULL["variants"])
    print(f"\nFig. 2, δ0/d = 1e-3, {n} grains; v̄max/v0 (plateau, RTOL {fig2.RTOL:g})")
    ref = {}
    for case in cases:
        sim, cpu, s = _run(fig2.scenario(1e-3, n, case).with_values(FIG2_REFERENCE))
        ref[case] = fig2._plateau(_vmax(sim))
        print(f"  reference {case:14s} {ref[case].mean:.8f} grains {ref[case].start + 1}-"
              f"{ref[case].stop} dt {s['dt']:.3e} s ({s['integrator']}) CPU {cpu:.1f} s",
              flush=True)
    base_cpu = None
    base = {}
    for name, values in candidates.items():
        total = 0.0
        for case in cases:
            sc = fig2.scenario(1e-3, n, case)
            sim, cpu, s = _run(sc.with_values(values) if values else sc)
            total += cpu
            p = fig2._plateau(_vmax(sim))
            if not values:
                base[case] = p
            b = base[case]
            rel = p.mean / ref[case].mean - 1
            print(f"  {name:18s} {case:14s} {p.mean:.8f} (vs reference {rel:+.1e}, "
                  f"vs default dt {p.mean / b.mean - 1:+.1e}) grains {p.start + 1}-{p.stop} "
                  f"std {p.std:.1e} slope {p.slope_per_1000:.1e}; dt {s['dt']:.3e} s "
                  f"({s['integrator']}), CPU {cpu:.1f} s", flush=True)
        base_cpu = base_cpu or total
        print(f"  {name:18s} CPU {total:.1f} s, {base_cpu / total:.2f}x fewer than the default dt "
              f"(load {os.getloadavg()[0]:.1f})", flush=True)


def fig6_study(candidates: dict) -> None:
    from hertzchain.reproduce import fig6

    # FULL's sizes at the default step (FULL's own dt_fraction is one of the candidates)
    s = {**fig6.FULL, "dt_fraction": None}
    print(f"\nFig. 6, {len(s['alphas'])} α per series, {s['length']} grains past the interface")
    base = None
    base_cpu = None
    for name, values in candidates.items():
        total, rows, mono = 0.0, [], np.nan
        for which in ("alpha_rho", "alpha_kn"):
            for a in s["alphas"]:
                ar, ak = (a, 1.0) if which == "alpha_rho" else (1.0, a)
                sc = fig6.scenario(ar, ak, s)
                sim, cpu, summ = _run(sc.with_values(values) if values else sc)
                total += cpu
                r = fig6._speeds(ar, ak, s, fig6._passages(sim))
                rows.append(np.array([w[2:5] for w in r.windows]))
                if ar == ak == 1.0:
                    mono = r.far[2] / r.far[4] - 1
        if base is None:
            base, base_cpu = rows, total
        dv = max(np.max(np.abs(x[:, 0] - y[:, 0])) for x, y in zip(rows, base, strict=True))
        dr = max(np.max(np.abs(x[:, 0] / x[:, 2] - y[:, 0] / y[:, 2]))
                 for x, y in zip(rows, base, strict=True))
        drf = max(abs(x[-1, 0] / x[-1, 2] - y[-1, 0] / y[-1, 2])
                  for x, y in zip(rows, base, strict=True))
        dx = max(np.max(np.abs(x[:, 1] - y[:, 1])) / fig6.DELTA0_OVER_D
                 for x, y in zip(rows, base, strict=True))
        print(f"  {name:18s} CPU {total:6.1f} s ({base_cpu / total:.2f}x fewer); largest change: "
              f"V/c0L {dv:.1e}, V/V_Eq5 {dr:.1e} (farthest window {drf:.1e}), "
              f"ξ_max/ξ0 {dx:.1e}; dt {summ['dt']:.3e} s (load {os.getloadavg()[0]:.1f})",
              flush=True)
        near = max(abs(x[0, 0] / x[0, 2] - 1) for x in rows)
        far = max(abs(x[-1, 0] / x[-1, 2] - 1) for x in rows)
        print(f"  {'':18s} the report's |V_sim/V_Eq.5 - 1|: at most {near:.2%} (nearest "
              f"window), {far:.2%} (farthest); monodisperse {mono:+.1e}", flush=True)


def fig7_study(candidates: dict) -> None:
    from hertzchain.reproduce import fig7
    from hertzchain.runner import run_scenario
    from hertzchain.scenario import parse_scenario

    s = fig7.FULL
    pts = fig7.points(s["grid"], s["lim"])
    print(f"\nFig. 7, {len(pts)} points: transmitted/reflected labels")
    base, base_cpu = None, None
    for name, run in candidates.items():
        labels, total = [], 0.0
        for _, ar, ak in pts:
            sc = fig7.scenario(ar, ak, run)
            c0 = time.process_time()
            summ = run_scenario(parse_scenario(sc), threads=1)
            total += time.process_time() - c0
            labels.append((summ["transmitted"], summ["reflected"]))
        if base is None:
            base, base_cpu = labels, total
        diff = [(p, a, b) for p, a, b in zip(pts, labels, base, strict=True) if a != b]
        print(f"  {name:18s} CPU {total:6.1f} s ({base_cpu / total:.2f}x fewer); "
              f"{len(diff)} of {len(pts)} labels differ from the default dt's"
              + "".join(f"; {p[1]:.4g},{p[2]:.4g}: {a} (was {b})" for p, a, b in diff[:5])
              + f" (load {os.getloadavg()[0]:.1f})", flush=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fig2", action="store_true")
    ap.add_argument("--fig6", action="store_true")
    ap.add_argument("--fig7", action="store_true")
    args = ap.parse_args(argv)
    every = not (args.fig2 or args.fig6 or args.fig7)
    print(f"CPU: {cpu_name()}; load average {os.getloadavg()[0]:.1f}")
    import numba

    numba.set_num_threads(1)
    if args.fig2 or every:
        fig2_study(FIG2_CANDIDATES)
    if args.fig6 or every:
        fig6_study(FIG6_CANDIDATES)
    if args.fig7 or every:
        fig7_study(FIG7_CANDIDATES)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
