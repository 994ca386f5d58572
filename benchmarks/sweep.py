"""Sweep throughput: points per second with 1 and 2 Dask workers, and the scaling ratio.

    python benchmarks/sweep.py                 # synthetic CPU-bound points (numba kernel)
    python benchmarks/sweep.py --real          # the real runner on the fig7_map.toml chain

Each worker count gets its own LocalCluster (processes, 1 thread each), warmed up
first, so the timing is the steady-state throughput of ``run_sweep`` (submission,
execution, per-point record appends and the final table) without cluster start-up.
On a machine shared with other jobs, the ratio is only as good as the free cores: the
best of ``--repeat`` runs is reported, next to the same calls in bare processes
without Dask (the machine's own scaling at that moment).
"""

from __future__ import annotations

import argparse
import copy
import functools
import logging
import os
import sys
import tempfile
import time
from importlib.resources import files
from pathlib import Path

from hertzchain.sweep import (
    DEFAULT_POINT_FUNCTION,
    load_sweep_spec,
    parse_sweep_spec,
    resolve_point_function,
    run_sweep,
    tiny_scenario,
)
from hertzchain.sweep.engine import _warm


def synthetic_spec(n_points: int, offset: int):
    """n_points distinct interfaces (offset makes each run's ids new)."""
    base = {"chain": {"delta0_over_d": 1e-3, "sections": [{"n": 60}, {"n": 60}]},
            "initial": {"kind": "exact_wave", "center": 20, "velocity_max": 0.05},
            "run": {"t_end": 1e-4}}
    return parse_sweep_spec({"name": f"bench{offset}", "base": base, "sweep": {"axes": [
        {"path": "chain.sections.1.alpha_rho", "logspace": [0.2 + 1e-3 * offset, 5.0, n_points]},
    ]}})


def real_spec(n_points: int, offset: int):
    """Points of the Fig. 7 acceptance map (its base chain), along alpha_rho at alpha_kn = 1."""
    spec = load_sweep_spec(files("hertzchain") / "sweeps" / "fig7_map.toml")
    d = {"name": f"real{offset}", "base": copy.deepcopy(spec.base), "sweep": {"axes": [
        {"path": "chain.sections.1.alpha_rho",
         "logspace": [0.2 + 1e-3 * offset, 5.0, n_points]}]}}
    return parse_sweep_spec(d)


def measure(workers: int, spec, fn) -> tuple[float, float]:
    """(points per second, mean point wall time) on a warmed-up cluster of ``workers``."""
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      dashboard_address=":0", silence_logs=logging.ERROR) as cluster, \
            Client(cluster) as client, tempfile.TemporaryDirectory() as tmp:
        tiny = tiny_scenario(spec.point_table(spec.points()[0].values))
        if tiny is not None:
            client.run(functools.partial(_warm, fn, tiny))
        t0 = time.perf_counter()
        outcome = run_sweep(spec, out=Path(tmp), point_function=fn, client=client,
                            progress=False, warmup=None)
        elapsed = time.perf_counter() - t0
        from hertzchain.sweep import read_results

        res = read_results(outcome.table)
        if outcome.n_failed:
            print(f"  warning: {outcome.n_failed} points failed: {res['error'][~res.ok][0]}")
        return outcome.n_run / elapsed, float(res["point_wall_time"].mean())


def _call(fn, scenario):
    fn(scenario, out=None, progress=False)


def bare(workers: int, spec, fn) -> float:
    """Points per second of the same calls in bare processes (no Dask): the machine's
    own scaling, to tell CPU contention from scheduling overhead."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    scenarios = [p.scenario for p in spec.points()]
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
        tiny = tiny_scenario(spec.point_table(spec.points()[0].values))
        list(pool.map(functools.partial(_warm, fn), [tiny] * workers))
        t0 = time.perf_counter()
        list(pool.map(functools.partial(_call, fn), scenarios))
        return len(scenarios) / (time.perf_counter() - t0)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=None,
                        help="points per measurement (default 16)")
    parser.add_argument("--work", type=int, default=40_000_000,
                        help="grain-steps per synthetic point (default 4e7, ~0.25 s)")
    parser.add_argument("--workers", default="1,2", help="worker counts (default 1,2)")
    parser.add_argument("--real", action="store_true",
                        help=f"use the real runner ({DEFAULT_POINT_FUNCTION}) on the Fig. 7 "
                        "map's chain")
    parser.add_argument("--repeat", type=int, default=2,
                        help="repetitions; the best rate is reported (default 2)")
    parser.add_argument("--no-baseline", dest="baseline", action="store_false",
                        help="skip the same calls in bare processes (machine baseline)")
    args = parser.parse_args(argv)
    if args.real:
        fn = resolve_point_function(None)
        make, n, what = real_spec, args.points or 16, "real runner, fig7_map.toml chain"
    else:
        from hertzchain.sweep.synthetic import synthetic_point

        fn = functools.partial(synthetic_point, work=args.work)
        make, n, what = synthetic_spec, args.points or 16, f"synthetic, {args.work:.0e} grain-steps"
    counts = [int(w) for w in args.workers.split(",")]
    print(f"sweep benchmark ({what}); {n} points per run; {os.cpu_count()} cores; "
          f"load average {os.getloadavg()[0]:.2f}")
    rates, base = {}, {}
    for k, w in enumerate(counts):
        runs, bares = [], []
        for r in range(args.repeat):  # interleaved, so both see the same machine load
            runs.append(measure(w, make(n, 10 * k + r), fn))
            if args.baseline:
                bares.append(bare(w, make(n, k), fn))
        rate, per_point = max(runs)
        rates[w] = rate
        line = f"  {w} worker(s): {rate:7.3f} points/s  (mean point wall time {per_point:.3f} s)"
        if args.baseline:
            base[w] = max(bares)
            line += f"; bare processes without Dask {base[w]:7.3f} points/s"
        print(line)
    if 1 in rates and len(rates) > 1:
        for w in counts:
            if w != 1:
                text = f"  scaling {w} vs 1 worker(s): {rates[w] / rates[1]:.2f}x (ideal {w}x"
                if base:
                    text += f"; bare processes on this machine now: {base[w] / base[1]:.2f}x"
                print(text + ")")
    return 0


if __name__ == "__main__":
    sys.exit(main())
