"""Sweep throughput: points per second with 1 and 2 Dask workers, and the scaling ratio.

    python benchmarks/sweep.py                 # synthetic CPU-bound points (numba kernel)
    python benchmarks/sweep.py --real          # the real runner on the fig7_map.toml chain
    python benchmarks/sweep.py --ensemble      # random chains: ensemble vs one by one
    python benchmarks/sweep.py --ensemble --baseline-commit 8d39a16   # ... and vs that code

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
import json
import logging
import os
import shutil
import subprocess
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


ENSEMBLE_TARGET = 5.0
"""Points/s of an ensemble sweep over the same points run one by one, whole command timed."""


def ensemble_spec(n_points: int, offset: int, grains: int, ensemble: bool):
    """Random chains of ``grains`` grains (disorder_mass 0.08 and 0.1, a seed axis, an
    impact): ``n_points`` realisations, as an ``[ensemble]`` or as a plain seed axis."""
    base = {"chain": {"delta0_over_d": 1e-3,
                      "sections": [{"n": grains, "disorder_mass": 0.08}]},
            "initial": {"kind": "impact", "v0": 0.1},
            "run": {"t_end": 5e-6 * grains}, "models": {"theory": False}}
    seeds = n_points // 2
    axes = [{"path": "chain.sections.0.disorder_mass", "name": "disorder_mass",
             "values": [0.08, 0.1]}]
    first = 10_000 * (offset + 1)  # new seeds (new ids) in every measurement
    if ensemble:
        return parse_sweep_spec({"name": f"ens{offset}", "base": base,
                                 "sweep": {"axes": axes},
                                 "ensemble": {"seeds": seeds, "first_seed": first}})
    axes.append({"path": "chain.sections.0.seed", "name": "seed",
                 "values": list(range(first, first + seeds))})
    return parse_sweep_spec({"name": f"one{offset}", "base": base, "sweep": {"axes": axes}})


def kernel_rates(grains: int, realisations: int = 64) -> dict:
    """Grain-updates per CPU second: the ensemble kernel, the single-chain kernel on the
    same chains (one Simulation each, maxima only) and on a 10,000-grain chain."""
    import numpy as np

    import theory
    from discrete import Chain, Disorder, Recording, Section
    from discrete.ensemble import run_ensemble
    from discrete.initial import impact

    def sims(r, n, seed0=0):
        out = []
        for s in range(r):
            c = Chain.from_sections([Section(n, 5e-3, theory.PAPER_MATERIAL,
                                             disorder=Disorder(mass=0.09, seed=seed0 + s))],
                                    delta0=5e-6)
            init = impact(c, 0.1)
            init.v[:] += 1e-3 * np.sin(np.arange(n))  # every grain moves: whole window
            out.append(init.simulation(record=Recording(maxima=True), threads=1))
        return out

    steps = 2000
    ens = sims(realisations, grains)
    t_end = steps * min(s.dt for s in ens)
    run_ensemble(ens[:2], t_end)  # compiled / loaded
    t = time.process_time()
    res = run_ensemble(ens, t_end)
    batch = res.steps.sum() * grains / (time.process_time() - t)
    one = sims(8, grains)
    one[0].run(10 * one[0].dt, progress=False)
    one = sims(8, grains)
    t = time.process_time()
    for s in one:
        s.run(t_end, progress=False)
    single = sum(s.steps for s in one) * grains / (time.process_time() - t)
    big = sims(1, 10_000)[0]
    t = time.process_time()
    big.run(300 * big.dt, progress=False)
    large = big.steps * 10_000 / (time.process_time() - t)
    return {"ensemble": batch, "single": single, "single_1e4": large}


def _cpu() -> float:
    return time.process_time()


def measure(workers: int, spec, fn) -> tuple[float, float, float]:
    """(points per second, mean point wall time, CPU seconds a point) on a warmed-up
    cluster of ``workers``.

    The workers are warmed up by the spec's tiny scenario (the sweep engine's warm-up)
    and by its first point, so that no kernel the points need is compiled (or loaded
    from the cache) while the sweep is timed.

    The CPU time is that of the workers and of this process (client and scheduler)
    during the run: what the command costs, whatever else the machine is running.
    """
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      dashboard_address=":0", silence_logs=logging.ERROR) as cluster, \
            Client(cluster) as client, tempfile.TemporaryDirectory() as tmp:
        first = spec.points()[0]
        tiny = tiny_scenario(spec.point_table(first.values))
        for warm in ([] if tiny is None else [tiny]) + [first.scenario]:
            client.run(functools.partial(_warm, fn, warm))  # every kernel it needs compiled
        c0, m0 = sum(client.run(_cpu).values()), time.process_time()
        t0 = time.perf_counter()
        outcome = run_sweep(spec, out=Path(tmp), point_function=fn, client=client,
                            progress=False, warmup=None)
        elapsed = time.perf_counter() - t0
        cpu = sum(client.run(_cpu).values()) - c0 + time.process_time() - m0
        from hertzchain.sweep import read_results

        res = read_results(outcome.table)
        if outcome.n_failed:
            print(f"  warning: {outcome.n_failed} points failed: {res['error'][~res.ok][0]}")
        return (outcome.n_run / elapsed, float(res["point_wall_time"].mean()),
                cpu / max(outcome.n_run, 1))


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
    parser.add_argument("--ensemble", action="store_true",
                        help="random chains: an [ensemble] sweep against the same points "
                        "one by one (the default runner), one worker")
    parser.add_argument("--grains", type=int, default=200,
                        help="--ensemble: grains per chain (default 200)")
    parser.add_argument("--repeat", type=int, default=2,
                        help="repetitions; the best rate is reported (default 2)")
    parser.add_argument("--no-baseline", dest="baseline", action="store_false",
                        help="skip the same calls in bare processes (machine baseline)")
    parser.add_argument("--baseline-commit", metavar="REV", default=None,
                        help="--ensemble: also time the points one by one with the code of "
                        "commit REV (its packages exported to a temporary directory, run in "
                        "a child process), interleaved with the other rows")
    parser.add_argument("--one-by-one-child", type=int, default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.one_by_one_child is not None:  # (a child of --baseline-commit: that code)
        spec = ensemble_spec(args.points, args.one_by_one_child, args.grains, False)
        print(json.dumps(measure(1, spec, resolve_point_function(DEFAULT_POINT_FUNCTION))))
        return 0
    if args.ensemble:
        return ensemble_main(args)
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
        rate, per_point, _ = max(runs)
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


def export_commit(rev: str) -> Path:
    """The packages of commit ``rev`` of this repository in a new temporary directory
    (``git archive``: no work tree or checkout of this repository is touched)."""
    root = Path(__file__).resolve().parents[1]
    sha = subprocess.run(["git", "-C", str(root), "rev-parse", "--verify", f"{rev}^{{commit}}"],
                         capture_output=True, text=True)
    if sha.returncode:
        raise SystemExit(f"--baseline-commit: {rev!r} is not a commit of {root}: "
                         f"{sha.stderr.strip()}")
    tmp = Path(tempfile.mkdtemp(prefix=f"hertzchain-{sha.stdout.strip()[:9]}-"))
    try:
        archive = subprocess.run(["git", "-C", str(root), "archive", "--format=tar",
                                  sha.stdout.strip()], capture_output=True, check=True)
        subprocess.run(["tar", "-x", "-C", str(tmp)], input=archive.stdout, check=True)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return tmp


def measure_at(code: Path, n: int, offset: int, grains: int) -> tuple[float, float, float]:
    """:func:`measure` of the points one by one with the packages in ``code`` (a child
    process, its Dask workers too, importing them first)."""
    env = {**os.environ, "PYTHONPATH": str(code)}
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--one-by-one-child",
                          str(offset), "--points", str(n), "--grains", str(grains)],
                         env=env, cwd=tempfile.gettempdir(), capture_output=True, text=True)
    if out.returncode:
        raise RuntimeError(f"the one-by-one sweep with the code of {code} failed "
                           f"(exit {out.returncode}):\n{out.stderr[-3000:]}")
    return tuple(json.loads(out.stdout.strip().splitlines()[-1]))


def ensemble_main(args) -> int:
    """``--ensemble``: points/s of an ensemble sweep against one by one, and kernel rates.

    With ``--baseline-commit REV`` the points one by one are also timed with the code
    of commit REV (:func:`export_commit`, :func:`measure_at`; the same spec, the same
    chains), interleaved with the other rows, and the ensemble's ratio to that row is
    printed beside the strict one (the same code one by one).
    """
    from hertzchain.sweep.ensemble import ENSEMBLE_POINT_FUNCTION

    n = args.points or 256
    print(f"ensemble benchmark: {n} random {args.grains}-grain chains (disorder_mass 0.08, "
          f"0.1; a seed axis; impact), 1 worker; load average {os.getloadavg()[0]:.2f}")
    one_fn = resolve_point_function(DEFAULT_POINT_FUNCTION)
    ens_fn = resolve_point_function(ENSEMBLE_POINT_FUNCTION)
    rates: dict[str, list] = {"one by one": [], "ensemble": []}
    old = None
    if args.baseline_commit:
        old = export_commit(args.baseline_commit)
        base_row = f"one by one at {args.baseline_commit}"
        rates[base_row] = []
    try:
        for r in range(args.repeat):  # interleaved: all rows see the same machine load
            rates["one by one"].append(measure(1, ensemble_spec(n, 2 * r, args.grains, False),
                                               one_fn))
            rates["ensemble"].append(measure(1, ensemble_spec(n, 2 * r + 1, args.grains,
                                                              True), ens_fn))
            if old is not None:
                rates[base_row].append(measure_at(old, n, 2 * r, args.grains))
    finally:
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    best = {k: max(v) for k, v in rates.items()}
    cpu = {k: min(x[2] for x in v) for k, v in rates.items()}
    for k, (rate, per_point, _) in best.items():
        print(f"  {k:10s}: {rate:8.1f} points/s ({1e3 / rate:6.1f} ms a point; mean "
              f"recorded point wall time {1e3 * per_point:.1f} ms; CPU {1e3 * cpu[k]:.1f} "
              "ms a point, workers + client + scheduler)")
    for k in rates:
        if k == "ensemble":
            continue
        ratio = best["ensemble"][0] / best[k][0]
        print(f"  ensemble / {k}: {ratio:.2f}x points/s (target >= {ENSEMBLE_TARGET:g}x: "
              f"{'met' if ratio >= ENSEMBLE_TARGET else 'NOT met'}); in CPU time a point "
              f"{cpu[k] / cpu['ensemble']:.2f}x")
    k = kernel_rates(args.grains)
    print(f"  kernel, grain-updates per CPU second: ensemble {k['ensemble']:.3g}; "
          f"single chain on the same chains {k['single']:.3g} "
          f"(ensemble/single {k['ensemble'] / k['single']:.2f}x); single chain of 10,000 "
          f"grains {k['single_1e4']:.3g} (ensemble/that {k['ensemble'] / k['single_1e4']:.2f}x)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
