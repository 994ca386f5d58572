"""Throughput of the discrete solver's production kernel, with the NumPy step beside it.

What is measured: grain-updates per second (grains in the active window × steps / wall
time) of :meth:`discrete.Simulation.run` — the production path, with the recording the
paper needs switched on: per-grain running maxima of v and u (Fig. 2), a snapshot
trigger (``WaveAt`` on the middle grain, tested every step; its threshold is never
reached, so it never fires) and the energy monitor (total and modified energy every
10,000 steps).  The chain is the paper's two-section chain (3/4 of the grains on the
left, α_ρ = 5 on the right, δ0^L/d = 1e-3) with random grain velocities (normal,
σ = 1 mm/s, seeded) *everywhere*: the active window covers all N grains at every step
(checked).  A third kernel row keeps the refined maxima of v between the steps as well
(``Recording(refined_maxima=True)``; what an rtol run records): on this
chain about 1 % of the grains reach a new maximum at every step, a worst case for its
per-step search.  The baseline is the plain NumPy velocity-Verlet step
(:mod:`discrete.reference`) on the same chain and state, measured in the same run,
repeats interleaved with the kernel's.  Rates are the best of ``--repeats`` repeats
(the medians are printed too); compilation is excluded (a warm-up run first).

Threads: ``--threads 2`` also measures ``Simulation(threads=2)`` (temporally blocked
kernel on both cores) beside ``threads=1`` and prints the 2-thread / 1-thread ratio;
``--threshold-scan`` measures that ratio over window sizes (the basis of
``discrete.simulation.PARALLEL_MIN_GRAINS``).  The machine is shared: the load average
(``os.getloadavg``) is printed before and after, and ratios are measured in one run.

Usage::

    python benchmarks/kernel.py                      # table at N = 1e4 and 1e5
    python benchmarks/kernel.py --grains 10000 --json
    python benchmarks/kernel.py --grains 50000 --threads 2
    python benchmarks/kernel.py --threshold-scan
    python benchmarks/kernel.py --roofline           # what limits the kernel, and C
    python benchmarks/kernel.py --roofline --grains 10000 --cpu native --cpu znver3
        # also the AVX2 code path, emulated on this machine

``--roofline`` times, in CPU seconds, a bare C velocity Verlet (``leapfrog.c`` beside this
script; compiled at run time with ``gcc -O3 -march=<cpu> -fno-math-errno`` into a
temporary directory, loaded with ctypes; skipped, and said so, without gcc) after
checking it against the kernel (bitwise with ``-ffp-contract=off``, to 1e-9 with the
FMAs gcc makes by default, which is the build timed), our bare kernel, the paper
recording and that recording plus Table 2's energy grid, and their ratios to C.
``--cpu NAME`` (not ``native``) runs all of it in a subprocess for another CPU kind:
numba with ``NUMBA_CPU_NAME=NAME`` and this host's features minus AVX-512
(``NUMBA_CPU_NAME`` alone keeps the host's features), a fresh numba cache so that the
kernel's assembly can be inspected (its zmm and masked-store counts are printed), gcc
``-march=NAME``.
This is an emulation: the other kind's code path on this machine's cores and memory.
    python benchmarks/kernel.py --baseline-tree /tmp/old --grains 10000
        # this code against another checkout of the package (e.g. ``git archive <commit>
        # | tar -x -C /tmp/old``), in one run: rounds of the two alternate, each in its
        # own process (PYTHONPATH=<tree>), and the ratio of the best rates is printed
    python benchmarks/kernel.py --compile --baseline-tree /tmp/old --rounds 3 [--cpu znver3]
        # the first compile (cold numba cache, CPU s) of both codes, alternating

``--baseline-tree`` is how a change to the kernels is checked for speed: both codes run
this same script (which uses only the public API of ``discrete``), on the same machine,
interleaved, so that the machine's load drifts equally over both.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

from _machine import cpu_name  # (before this folder leaves sys.path, if it does)

# this folder is not a package: keep it off the import path (benchmarks/*.py named like
# the packages they measure would shadow them)
_here = Path(__file__).resolve().parent
sys.path[:] = [p for p in sys.path if Path(p or ".").resolve() != _here]

import numpy as np  # noqa: E402

from discrete import Chain, Recording, Simulation, WaveAt  # noqa: E402
from discrete import reference as R  # noqa: E402

SIGMA_V = 1e-3  # m/s, random grain velocities everywhere


def machine() -> dict:
    """CPU model, cores and load (for the README table)."""
    return {"cpu": cpu_name(), "cores": os.cpu_count(), "load": os.getloadavg()}


def chain_and_state(n: int, seed: int = 0):
    """The benchmark chain and its initial velocities (module docstring)."""
    n_right = n // 4
    ch = Chain.two_section(n - n_right, n_right, alpha_rho=5.0, delta0_over_d=1e-3)
    v = np.random.default_rng(seed).normal(0.0, SIGMA_V, n)
    return ch, v


def production(ch: Chain, v: np.ndarray, threads: int, recording: bool = True,
               refined: bool = False) -> Simulation:
    """A warmed-up Simulation with the paper's recording (or none; or with refined maxima).

    ``refined``: also the refined maxima of v between the steps (``Recording(
    refined_maxima=True)``; off by default, on in rtol runs).
    """
    n = ch.n
    extra = {"refined_maxima": True} if refined else {}
    rec = (Recording(maxima=True, snapshots=[WaveAt(n // 2, threshold=1.0)],
                     monitor_every=10_000, **extra) if recording
           else Recording(maxima=False, monitor_every=10**9))
    sim = Simulation(ch, v=v.copy(), record=rec, threads=threads)
    sim.run(max_steps=600, progress=False)  # compile / load the kernels, enter the regime
    return sim


def time_sim(sim: Simulation, steps: int) -> float:
    """Grain-updates per second of ``steps`` steps (the window must be the whole chain)."""
    t0 = time.perf_counter()
    sim.run(max_steps=steps, progress=False)
    dt = time.perf_counter() - t0
    lo, hi = sim.window
    if (lo, hi) != (0, sim.chain.n - 1):
        raise RuntimeError(f"active window {lo, hi} is not the whole chain")
    return sim.chain.n * steps / dt


class NumpyStep:
    """The NumPy reference step (discrete.reference) on the same chain and state."""

    def __init__(self, ch: Chain, v: np.ndarray, dt: float):
        self.args = (ch.mass, ch.k, ch.delta0)
        self.u = np.zeros(ch.n)
        self.v = v.copy()
        self.a = R.accelerations(self.u, *self.args)
        self.dt = dt
        self.n = ch.n

    def rate(self, steps: int) -> float:
        t0 = time.perf_counter()
        u, v, a = self.u, self.v, self.a
        for _ in range(steps):
            u, v, a = R.step(u, v, a, self.dt, *self.args)
        self.u, self.v, self.a = u, v, a
        return self.n * steps / (time.perf_counter() - t0)


def steps_for(n: int, rate: float, seconds: float) -> int:
    return max(20, int(math.ceil(seconds * rate / n)))


def measure(n: int, repeats: int, seconds: float, threads: int = 1) -> dict:
    """Kernel (threads=1, and ``threads`` if > 1) and NumPy rates, repeats interleaved."""
    ch, v = chain_and_state(n)
    sims = {1: production(ch, v, 1)}
    if threads > 1:
        sims[threads] = production(ch, v, threads)
    bare = production(ch, v, 1, recording=False)
    try:
        sims["refined"] = production(ch, v, 1, refined=True)
    except TypeError:  # a tree of before the refined maxima (--baseline-tree)
        pass
    ref = NumpyStep(ch, v, sims[1].dt)
    ref.rate(3)
    rates: dict = {key: [] for key in [*sims, "bare", "numpy"]}
    # step counts from a first estimate so that a repeat takes ~``seconds``
    est = {key: time_sim(sim, steps_for(n, 2e9, 0.05)) for key, sim in sims.items()}
    est["bare"] = time_sim(bare, steps_for(n, 2e9, 0.05))
    est["numpy"] = ref.rate(steps_for(n, 2e8, 0.05))
    for _ in range(repeats):
        for key, sim in sims.items():
            rates[key].append(time_sim(sim, steps_for(n, est[key], seconds)))
        rates["bare"].append(time_sim(bare, steps_for(n, est["bare"], seconds)))
        rates["numpy"].append(ref.rate(steps_for(n, est["numpy"], seconds)))
    return {"grains": n, "threads": threads, "dt": sims[1].dt,
            "best": {k: max(r) for k, r in rates.items()},
            "median": {k: float(np.median(r)) for k, r in rates.items()}}


def print_table(results: list[dict], load0, load1) -> None:
    m = machine()
    print(f"# {m['cpu']}, {m['cores']} cores; load average before {load0[0]:.2f} "
          f"{load0[1]:.2f} {load0[2]:.2f}, after {load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f}")
    print("# grain-updates/s, best (median) of the repeats; recording: maxima + WaveAt "
          "trigger + energy monitor; full-chain disturbance")
    head = (f"{'N':>8} {'kernel 1 thread':>20} {'no recording':>20} {'NumPy step':>20} "
            f"{'kernel/NumPy':>13} {'refined maxima':>20}")
    print(head)
    for r in results:
        b, md = r["best"], r["median"]
        print(f"{r['grains']:>8} {b[1]:>11.3e} ({md[1]:.2e}) {b['bare']:>11.3e} "
              f"({md['bare']:.2e}) {b['numpy']:>11.3e} ({md['numpy']:.2e}) "
              f"{b[1] / b['numpy']:>12.1f}x {b['refined']:>11.3e} ({md['refined']:.2e})")
        if r["threads"] > 1:
            t = r["threads"]
            print(f"{'':>8} {t} threads: {b[t]:.3e} ({md[t]:.2e}) — {t}-thread / 1-thread "
                  f"ratio {b[t] / b[1]:.2f} (best), {md[t] / md[1]:.2f} (median)")


def _ceilings():
    import numba

    @numba.njit(nogil=True)
    def sqrt_only(x, y, reps):  # one r·sqrt(r) per element: the kernel's one square root
        for _ in range(reps):
            for i in range(x.size):
                r = x[i]
                y[i] = r * np.sqrt(r)

    @numba.njit(nogil=True)
    def traffic(u, v, w, reps):  # the kernel's memory traffic: read u, v, max v; write u, v
        for _ in range(reps):
            for i in range(u.size):
                ui = u[i] + 1e-9 * v[i]
                u[i] = ui
                vi = v[i] - 1e-9 * ui
                v[i] = vi
                w[i] = np.fmax(w[i], vi)  # the kernel's running maximum (w = 1e9)

    return sqrt_only, traffic


# --------------------------------------------------------------- bare C reference
C_SOURCE = _here / "leapfrog.c"
"""The bare C velocity Verlet (same chain, force law, state layout; see its header)."""

GRID_EVERY = 20
"""Energy-grid row interval of the paper recording: Table 2's ``energy_every`` (the
densest grid the paper's runs record; the automatic one is a row per half grain transit)."""

GRID_COARSEN = 16
"""Grains per energy-grid column in the benchmark (keeps a benchmark's grid under the
runner's 2e7 entries; the per-row pass over all grains is the same for any value)."""

_AVX512_PREFIXES = ("avx512", "amx", "avx10", "evex512")


def emulated_features(cpu: str) -> str | None:
    """``NUMBA_CPU_FEATURES`` for ``--cpu``: this host's features without AVX-512.

    ``NUMBA_CPU_NAME`` alone keeps the *host's* feature list (numba passes both to
    LLVM), so AVX-512 would stay on; every avx512*/amx*/avx10*/evex512 feature is
    switched off here.  None for ``native``.
    """
    if cpu == "native":
        return None
    from numba.core.codegen import get_host_cpu_features

    out = []
    for f in get_host_cpu_features().split(","):
        name = f[1:]
        out.append("-" + name if name.startswith(_AVX512_PREFIXES) else f)
    return ",".join(out)


def build_c(march: str, contract: bool, outdir: str):
    """Compile :data:`C_SOURCE` with ``gcc -O3 -march=<march>``; the ctypes function.

    ``contract``: gcc's default ``-ffp-contract=fast`` (FMAs; what is timed); else
    ``-ffp-contract=off`` (the numba kernel's arithmetic, bit for bit: the check).
    Returns ``(leapfrog, zmm)``, zmm the number of zmm-register operands in the
    library's disassembly (None without objdump); None if gcc is absent.
    """
    import ctypes
    import shutil

    gcc = shutil.which("gcc")
    if gcc is None:
        return None
    lib = Path(outdir) / f"leapfrog_{march}_{'fma' if contract else 'nofma'}.so"
    flags = ["-O3", f"-march={march}", "-fno-math-errno", "-shared", "-fPIC",
             "-ffp-contract=" + ("fast" if contract else "off")]
    subprocess.run([gcc, *flags, str(C_SOURCE), "-o", str(lib), "-lm"], check=True)
    zmm = None
    if shutil.which("objdump"):
        asm = subprocess.run(["objdump", "-d", str(lib)], capture_output=True, text=True)
        zmm = asm.stdout.count("%zmm")
    f = ctypes.CDLL(str(lib)).leapfrog
    dp = np.ctypeslib.ndpointer(np.float64, flags="C_CONTIGUOUS")
    f.argtypes = [ctypes.c_long, ctypes.c_long, dp, dp, dp, dp, dp, dp, dp, dp,
                  ctypes.c_double, ctypes.c_double, ctypes.c_double]
    f.restype = None
    return f, zmm


class CStep:
    """The bare C leapfrog on a Simulation's chain and (u, v, a) state."""

    def __init__(self, fn, sim: Simulation):
        self.fn = fn
        self.n = sim.chain.n
        self.u, self.v, self.a = sim.u.copy(), sim.v.copy(), sim.a.copy()
        self.f = np.zeros(self.n + 1)
        self.const = (np.ascontiguousarray(1.0 / sim.chain.mass), sim._k, sim._d0, sim._f0)
        self.walls = (float(sim.wall_left), float(sim.wall_right), float(sim.dt))

    def run(self, steps: int) -> None:
        self.fn(self.n, steps, self.u, self.v, self.a, self.f, *self.const, *self.walls)

    def rate(self, steps: int) -> float:
        """Grain-updates per CPU second (``time.process_time``)."""
        t0 = time.process_time()
        self.run(steps)
        return self.n * steps / (time.process_time() - t0)


def check_c(fn_exact, fn_fast, ch: Chain, v: np.ndarray, steps: int = 500) -> dict:
    """The C leapfrog against our kernel after ``steps`` steps from the same state.

    Raises RuntimeError unless the ``-ffp-contract=off`` build equals the kernel bit for
    bit and the timed (FMA) build agrees to round-off: max |Δu|, |Δv| <= 1e-9 of max
    |u|, |v| (the FMAs change the last bit of a few products per step; growth over 500
    steps of a chain at rest but for σ = 1 mm/s noise stays many orders below this).
    """
    sim = Simulation(ch, v=v.copy(), record=Recording(maxima=False, monitor_every=10**9),
                     threads=1)
    exact, fast = CStep(fn_exact, sim), CStep(fn_fast, sim)
    sim.run(max_steps=steps, progress=False)
    exact.run(steps)
    fast.run(steps)
    bitwise = all(np.array_equal(x, y) for x, y in
                  ((exact.u, sim.u), (exact.v, sim.v), (exact.a, sim.a)))
    du = float(np.max(np.abs(fast.u - sim.u)) / np.max(np.abs(sim.u)))
    dv = float(np.max(np.abs(fast.v - sim.v)) / np.max(np.abs(sim.v)))
    if not bitwise or not (du <= 1e-9 and dv <= 1e-9):
        raise RuntimeError(f"the C leapfrog disagrees with the kernel after {steps} steps: "
                           f"bitwise (fp-contract=off) {bitwise}, FMA build relative "
                           f"max |du| {du:.2e}, |dv| {dv:.2e} (allowed 1e-9)")
    return {"bitwise_nofma": bitwise, "rel_du_fma": du, "rel_dv_fma": dv}


def grid_recording(n: int) -> Recording:
    """The paper recording plus Table 2's energy grid (a row every :data:`GRID_EVERY`
    steps; the paper's 10,000-grain runs, Figs. 2b and 5, record no grid)."""
    return Recording(maxima=True, snapshots=[WaveAt(n // 2, threshold=1.0)],
                     monitor_every=10_000, energy_every=GRID_EVERY,
                     energy_coarsen=GRID_COARSEN)


def kernel_asm(sim: Simulation) -> dict:
    """Counts in the assembly of the kernel the Simulation runs: zmm-register operands
    (``zmm``: AVX-512 code) and masked stores (``maskmov``: ``vmaskmovpd``/``vmaskmovps``,
    microcoded on AMD; the running maxima must not become one, ``discrete.kernels._raised``).

    None each if numba loaded it from its disk cache (no assembly kept): ``--cpu`` runs use
    a fresh cache directory so that the emulated code is always inspected.
    """
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numba warns (and returns junk) for cached code
        try:
            asm = sim._kernel(1).inspect_asm()
        except Exception:
            asm = None
    if not asm:
        return {"zmm": None, "maskmov": None}
    return {"zmm": sum(a.count("%zmm") for a in asm.values()),
            "maskmov": sum(a.count("vmaskmov") for a in asm.values())}


def cpu_rates(grains: list[int], repeats: int, march: str) -> list[dict]:
    """Per N: the ceilings, the bare C leapfrog, our bare kernel and the paper recording.

    Rates in grain-updates per CPU second (``time.process_time``; one thread each), the
    best of ``repeats``, the three codes' repeats interleaved.
    """
    import tempfile

    sqrt_only, traffic = _ceilings()
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        built = build_c(march, True, tmp)
        exact = build_c(march, False, tmp) if built else None
        for n in grains:
            x = np.random.default_rng(0).uniform(1.0, 2.0, n)
            y, z = np.zeros(n), np.full(n, 1e9)
            reps = max(1, int(2e8 / n))
            sqrt_only(x, y, 1)
            traffic(x.copy(), y, z, 1)
            r_sqrt = r_mem = 0.0
            for _ in range(repeats):
                t0 = time.process_time()
                sqrt_only(x, y, reps)
                r_sqrt = max(r_sqrt, n * reps / (time.process_time() - t0))
                u = x.copy()
                t0 = time.process_time()
                traffic(u, y, z, reps)
                r_mem = max(r_mem, n * reps / (time.process_time() - t0))
            ch, v = chain_and_state(n)
            bare = production(ch, v, 1, recording=False)
            full = production(ch, v, 1)
            grid = Simulation(ch, v=v.copy(), record=grid_recording(n), threads=1)
            grid.run(max_steps=600, progress=False)
            row = {"grains": n, "sqrt": r_sqrt, "traffic": r_mem, "march": march,
                   **{f"{k}_kernel": x for k, x in kernel_asm(full).items()}}
            cref = None
            if built:
                row["check"] = check_c(exact[0], built[0], ch, v)
                row["zmm_c"] = built[1]
                cref = CStep(built[0], bare)
                cref.run(600)
            steps = steps_for(n, 2.5e9, 0.3)
            rates = {"c": [], "bare": [], "recording": [], "grid": []}
            for _ in range(repeats):
                if cref is not None:
                    rates["c"].append(cref.rate(steps))
                for key, sim in (("bare", bare), ("recording", full), ("grid", grid)):
                    t0 = time.process_time()
                    time_sim(sim, steps)
                    rates[key].append(n * steps / (time.process_time() - t0))
            row.update({k: (max(r) if r else None) for k, r in rates.items()})
            out.append(row)
    return out


def _cpu_subprocess(cpu: str, grains: list[int], repeats: int) -> list[dict]:
    """:func:`cpu_rates` for an emulated CPU kind in a fresh process (module docstring)."""
    import tempfile

    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CPU_NAME=cpu, NUMBA_CPU_FEATURES=emulated_features(cpu),
                   NUMBA_CACHE_DIR=cache)
        cmd = [sys.executable, str(Path(__file__).resolve()), "--roofline", "--json",
               "--cpu", cpu, "--repeats", str(repeats)]
        for n in grains:
            cmd += ["--grains", str(n)]
        out = subprocess.run(cmd, env=env, capture_output=True, text=True)
        if out.returncode != 0:
            raise RuntimeError(f"--cpu {cpu} subprocess failed:\n{out.stderr[-3000:]}")
        return json.loads(out.stdout.strip().splitlines()[-1])


def roofline(grains: list[int], repeats: int, cpus: list[str], as_json: bool) -> None:
    """What limits the kernel: the bare C leapfrog, a square-root-only loop and a loop
    with the kernel's memory traffic beside our bare kernel and the paper recording.

    ``cpus``: ``native`` (this process) and/or a CPU name to emulate (e.g. ``znver3``:
    numba with ``NUMBA_CPU_NAME`` and this host's features minus AVX-512, gcc
    ``-march=znver3``), each in its own process, in this one run.
    """
    emulated = os.environ.get("NUMBA_CPU_NAME")
    if as_json:  # (the --cpu subprocess, or a single native measurement)
        print(json.dumps(cpu_rates(grains, repeats, emulated or "native")))
        return
    load0 = os.getloadavg()
    results = []
    for cpu in cpus:
        rows = (cpu_rates(grains, repeats, "native") if cpu == "native"
                else _cpu_subprocess(cpu, grains, repeats))
        results += rows
    load1 = os.getloadavg()
    m = machine()
    print(f"# {m['cpu']} ({platform.machine()}), host CPU {_host_cpu()}; load average "
          f"before {load0[0]:.2f}, after {load1[0]:.2f}")
    print("# grain-updates per CPU second, best of repeats, one thread; C: gcc -O3 "
          "-march=<cpu> -fno-math-errno, checked against the kernel (bitwise without FMA "
          "contraction, to round-off with it)")
    print("# recording: the paper's 10,000-grain runs (Figs. 2b, 5): running maxima of v "
          "and u, WaveAt trigger, energy monitor; +grid: also Table 2's energy grid, a row "
          f"every {GRID_EVERY} steps")
    if any(c != "native" for c in cpus):
        print("# an emulated CPU kind runs this machine's cores and memory system with "
              "that CPU's code path (numba NUMBA_CPU_NAME + AVX-512 features off, gcc "
              "-march): the AVX2 code, not that machine's timings")
    print(f"{'cpu':>8} {'N':>8} {'sqrt only':>10} {'traffic':>10} {'bare C':>10} "
          f"{'bare':>10} {'recording':>10} {'+grid':>10} {'bare/C':>7} {'rec/C':>7} "
          f"{'+grid/C':>7} {'zmm kern/C':>11} {'maskmov':>7}")
    for r in results:
        c = r.get("c")
        def ratio(x, c=c):
            return f"{x / c:>7.2f}" if c else f"{'-':>7}"

        cs = f"{c:>10.3e}" if c else f"{'skipped':>10}"
        print(f"{r['march']:>8} {r['grains']:>8} {r['sqrt']:>10.3e} {r['traffic']:>10.3e} "
              f"{cs} {r['bare']:>10.3e} {r['recording']:>10.3e} {r['grid']:>10.3e} "
              f"{ratio(r['bare'])} {ratio(r['recording'])} {ratio(r['grid'])} "
              f"{str(r.get('zmm_kernel')):>5}/{r.get('zmm_c')} "
              f"{str(r.get('maskmov_kernel')):>7}")
    if not any(r.get("c") for r in results):
        print("# gcc not found: the bare C row is skipped")


def _host_cpu() -> str:
    import llvmlite.binding as llb

    return llb.get_host_cpu_name()


def threshold_scan(repeats: int, seconds: float) -> None:
    print("# 2-thread / 1-thread ratio of Simulation.run (best of repeats, recording on)")
    print(f"{'N':>8} {'1 thread':>12} {'2 threads':>12} {'ratio':>7}")
    for n in (5_000, 10_000, 20_000, 50_000, 100_000):
        ch, v = chain_and_state(n)
        s1 = production(ch, v, 1)
        s2 = production(ch, v, 2)
        s2.min_parallel = 0  # force the threaded kernel at every size
        r1, r2 = [], []
        est = time_sim(s1, steps_for(n, 2e9, 0.05))
        for _ in range(repeats):
            r1.append(time_sim(s1, steps_for(n, est, seconds)))
            r2.append(time_sim(s2, steps_for(n, est, seconds)))
        print(f"{n:>8} {max(r1):>12.3e} {max(r2):>12.3e} {max(r2) / max(r1):>7.2f}")


def _run_tree(tree: str | None, n: int, repeats: int, seconds: float) -> dict:
    """This script's --json measurement in a fresh process, on ``tree``'s packages or ours."""
    env = dict(os.environ)
    if tree is not None:
        env["PYTHONPATH"] = str(Path(tree).resolve()) + os.pathsep + env.get("PYTHONPATH", "")
    cmd = [sys.executable, str(Path(__file__).resolve()), "--grains", str(n), "--json",
           "--repeats", str(repeats), "--seconds", str(seconds)]
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def compare_trees(tree: str, grains: list[int], rounds: int, repeats: int,
                  seconds: float) -> None:
    """Best rates of this code and of ``tree``'s, rounds alternating; their ratio."""
    m = machine()
    print(f"# {m['cpu']}, {m['cores']} cores; baseline: packages of {tree}")
    print(f"{'N':>8} {'kind':>10} {'baseline':>11} {'this code':>11} {'ratio':>7}")
    for n in grains:
        best = {"base": {}, "new": {}}
        for _ in range(rounds):
            for who, t in (("base", tree), ("new", None)):
                r = _run_tree(t, n, repeats, seconds)
                for kind in ("grain_updates_per_s", "bare_grain_updates_per_s",
                             "refined_grain_updates_per_s"):
                    if r.get(kind) is not None:
                        best[who][kind] = max(best[who].get(kind, 0.0), r[kind])
        for kind, label in (("grain_updates_per_s", "recording"),
                            ("bare_grain_updates_per_s", "bare")):
            if kind in best["base"] and kind in best["new"]:
                b, c = best["base"][kind], best["new"][kind]
                print(f"{n:>8} {label:>10} {b:>11.3e} {c:>11.3e} {c / b:>7.3f}")
        if "refined_grain_updates_per_s" in best["new"]:  # (this code only)
            c = best["new"]["refined_grain_updates_per_s"]
            b = best["base"]["grain_updates_per_s"]
            print(f"{n:>8} {'refined':>10} {b:>11.3e} {c:>11.3e} {c / b:>7.3f}   "
                  f"(recording + refined maxima against the baseline's recording)")
    load = os.getloadavg()
    print(f"# load average after: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")


COMPILE_GRAINS = 2_000
"""Chain length of the ``--compile`` run (what is compiled does not depend on it)."""


def first_run_cpu() -> dict:
    """CPU seconds of a first paper-recording run (:func:`production`), this process.

    Run by :func:`compare_compile` in a fresh process with an empty ``NUMBA_CACHE_DIR``:
    the time is numba's compile of the kernels a recording run calls, plus 600 steps
    of :data:`COMPILE_GRAINS` grains (~1 ms).
    """
    ch, v = chain_and_state(COMPILE_GRAINS)
    t0 = time.process_time()
    production(ch, v, 1)
    return {"first_run_cpu_s": time.process_time() - t0}


def compare_compile(tree: str | None, rounds: int, cpu: str) -> None:
    """First-compile CPU time (cold cache) of this code, and of ``tree``'s, alternating.

    Each measurement is a fresh process with a fresh, empty numba cache directory
    (``--compile-json``); ``cpu`` not ``native``: numba's code path for that CPU kind, as
    in ``--roofline --cpu`` (the compile time depends on the code LLVM makes).
    """
    import tempfile

    whos = [("this code", None)] + ([("baseline", tree)] if tree else [])
    times: dict[str, list[float]] = {w: [] for w, _ in whos}
    load0 = os.getloadavg()
    for _ in range(rounds):
        for who, t in whos:
            with tempfile.TemporaryDirectory() as cache:
                env = dict(os.environ, NUMBA_CACHE_DIR=cache)
                if cpu != "native":
                    env.update(NUMBA_CPU_NAME=cpu, NUMBA_CPU_FEATURES=emulated_features(cpu))
                if t is not None:
                    env["PYTHONPATH"] = (str(Path(t).resolve()) + os.pathsep
                                         + env.get("PYTHONPATH", ""))
                out = subprocess.run([sys.executable, str(Path(__file__).resolve()),
                                      "--compile-json"], env=env, capture_output=True,
                                     text=True, check=True).stdout
                times[who].append(json.loads(out.strip().splitlines()[-1])[
                    "first_run_cpu_s"])
    load1 = os.getloadavg()
    print(f"# {cpu_name()}; code path {cpu}; first run of {COMPILE_GRAINS} grains with the "
          f"paper recording, fresh numba cache, CPU s; load {load0[0]:.2f} -> {load1[0]:.2f}")
    for who, _ in whos:
        x = sorted(times[who])
        print(f"{who:>10}: best {x[0]:.2f} s, median {x[len(x) // 2]:.2f} s  "
              f"({', '.join(f'{y:.2f}' for y in times[who])})")


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--grains", type=int, action="append",
                   help="chain length (repeatable); default 10000 and 100000")
    p.add_argument("--threads", type=int, default=1, help="also measure this many threads")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--seconds", type=float, default=0.4, help="wall time per repeat")
    p.add_argument("--json", action="store_true", help="one JSON object (one --grains)")
    p.add_argument("--threshold-scan", action="store_true")
    p.add_argument("--roofline", action="store_true",
                   help="the kernel beside a bare C leapfrog and its compute and memory "
                        "ceilings")
    p.add_argument("--cpu", action="append",
                   help="with --roofline: 'native' and/or a CPU kind to emulate (e.g. "
                        "znver3: AVX2, no AVX-512), each in its own process (repeatable; "
                        "default native)")
    p.add_argument("--baseline-tree", metavar="DIR",
                   help="compare with the packages of another checkout (see the docstring)")
    p.add_argument("--rounds", type=int, default=5, help="alternating rounds (--baseline-tree)")
    p.add_argument("--compile", action="store_true",
                   help="first-compile CPU time, cold cache (with --baseline-tree: both "
                        "codes, alternating; --rounds rounds; --cpu: one code path)")
    p.add_argument("--compile-json", action="store_true", help=argparse.SUPPRESS)
    a = p.parse_args(argv)
    if a.compile_json:
        print(json.dumps(first_run_cpu()))
        return
    if a.compile:
        compare_compile(a.baseline_tree, a.rounds, (a.cpu or ["native"])[0])
        return
    if a.baseline_tree:
        compare_trees(a.baseline_tree, a.grains or [10_000], a.rounds, a.repeats, a.seconds)
        return
    if a.threshold_scan:
        threshold_scan(a.repeats, a.seconds)
        return
    if a.roofline:
        roofline(a.grains or [10_000, 100_000, 1_000_000], a.repeats, a.cpu or ["native"],
                 a.json)
        return
    grains = a.grains or ([50_000] if a.threads > 1 else [10_000, 100_000])
    if a.json and len(grains) != 1:
        p.error("--json takes exactly one --grains")
    load0 = os.getloadavg()
    results = [measure(n, a.repeats, a.seconds, a.threads) for n in grains]
    load1 = os.getloadavg()
    if a.json:
        r = results[0]
        out = {"grains": r["grains"], "grain_updates_per_s": r["best"][1],
               "refined_grain_updates_per_s": r["best"].get("refined"),
               "bare_grain_updates_per_s": r["best"]["bare"],
               "baseline_numpy_grain_updates_per_s": r["best"]["numpy"]}
        if a.threads > 1:
            out["threads"] = a.threads
            out["grain_updates_per_s_threads"] = r["best"][a.threads]
            out["thread_ratio"] = r["best"][a.threads] / r["best"][1]
        print(json.dumps(out))
    else:
        print_table(results, load0, load1)


if __name__ == "__main__":
    main()
