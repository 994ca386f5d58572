"""The paper's largest runs (Fig. 5, 50,000 grains) timed, with the time-step study behind them.

Set-up (paper Section 4, Fig. 5): two-section chain of 50,000 grains with the interface
between grains 35,000 and 35,001 (1-based; 0-based grains 0..34,999 are the left
section), δ0^L/d = 1e-3, the four points a–d (α_ρ = 0.2, 5 at α_kn = 1; α_kn = 0.2, 5 at
α_ρ = 1; ``theory.PAPER_POINTS``).  Incident wave: the paper's settled solitary wave
(impact at 1 m/s on a monodisperse chain, settled over 10,000 grains, cut with ±40
grains; ``discrete.cut_wave``, computed once and cached on disk) with its peak at grain
34,700, 300 grains before the interface.  Each run stops when the transmitted front's
velocity peak reaches grain 49,900 (``WaveAt(49_899)``, with its snapshot); recording:
per-grain maxima, snapshots at the front's passage at grains 39,900 and 49,900 (front
speed), energy monitor.  Reported per case: wall time, steps, kinetic / potential /
total energy of each section at the final snapshot (J; docs/physics.md §6), the transmitted
front's speed (grains/s, from the sub-grid peak positions in the two snapshots), the
energy drift.

Production time stepping (``PRODUCTION``): the 4th-order method of Blanes & Moan
(``integrator="blanes_moan4"``) at dt = 0.096·2π/ω_max (48 × velocity Verlet's default,
6 force evaluations per step: 1/8 of the force evaluations of velocity Verlet at its
default dt), chosen from the dt study below, where it is ~100× more accurate than
velocity Verlet at the same cost.  ``--verlet`` also times velocity Verlet at its
default dt for comparison.

dt study (``--dt-study``): a dt = 1e-9 s run of 50,000 grains (~1e12–1e13 grain
updates) is out of reach, so the same physics is run on a reduced chain — the same
sections and incident wave, the front followed for D = 1,000 grains past the interface
(left section long enough that the reflected wave stays in it) — to the same final
time T with velocity Verlet at dt = 1e-9 s (the reference) and with each method at
several dt (all dividing T, so every run ends at exactly T; front speed from the
snapshots at 3T/4 and T).  Printed: the relative difference of each energy and of the
front speed to the reference, the fitted order, and whether the production dt agrees
to 4 significant digits (relative difference < 5e-5).  A fifth, study-only case
("a0") repeats it at δ0 = 0 with gaps opening at the interface, where the Hertz force
is only C¹ and the 4th-order methods lose their order.  For the full runs
(``--richardson``): each case again at dt/2; the difference estimates the production
error (for a 4th-order method error(dt) ≈ 16/15 |x(dt) - x(dt/2)|).

Continuum accuracy (``--continuum``): the continuum beside each panel (corrected Eq. 4,
Rosenau form, 3 nodes per grain; ``[models]`` of ``paper/fig5.toml``) at the --quick
geometry (10,000 grains, the same physics at 1/5 scale), each case a–d with the
continuum's ``[models] integrator`` / ``dt_safety`` variants of :data:`CONTINUUM_VARIANTS`
against a converged reference (Blanes–Moan-4 at ``dt_safety`` 0.2: its time error
(1.45/0.2)^4 ≈ 2,800 × below the production one's).  Printed per variant: the L2
relative difference of the final grain velocities to the reference, the force
evaluations per 1/ω_max (S / (2 dt_safety)) and the CPU seconds of the continuum run
with their ratio to a Yoshida-4 run at ``dt_safety`` 0.5, measured in the same run.

Usage::

    python benchmarks/fig5_full.py                 # dt study, full runs timed, Richardson
    python benchmarks/fig5_full.py --continuum     # the continuum's time-step accuracy
    python benchmarks/fig5_full.py --full          # only the four timed full runs
    python benchmarks/fig5_full.py --dt-study --cases b
"""

from __future__ import annotations

import argparse
import math
import os
import re
import sys
import tempfile
import time
from pathlib import Path

_here = Path(__file__).resolve().parent
from _machine import cpu_name  # noqa: E402  (before this folder leaves sys.path)

sys.path[:] = [p for p in sys.path if Path(p or ".").resolve() != _here]

import numpy as np  # noqa: E402

import theory  # noqa: E402
from discrete import AtTime, Chain, Recording, WaveAt, default_dt  # noqa: E402
from discrete.diagnostics.waves import leading_pulse  # noqa: E402
from discrete.energy import grain_energy  # noqa: E402
from discrete.initial import cut_wave  # noqa: E402
from discrete.integrators import get_integrator  # noqa: E402

N_LEFT, N_RIGHT, CENTRE = 35_000, 15_000, 34_700
FRONT_1, FRONT_2 = 39_899, 49_899  # 0-based grains 39,900 and 49,900 (1-based)
DELTA0 = 1e-3
CASES = "abcd"
PRODUCTION = ("blanes_moan4", 0.096)
"""(integrator, dt fraction of the shortest contact period) of the timed runs."""
CACHE = Path(os.environ.get("HERTZCHAIN_BENCH_CACHE",
                            Path(tempfile.gettempdir()) / "hertzchain-bench"))
REL_4_DIGITS = 5e-5
CONTINUUM_REFERENCE = ("blanes_moan4", 0.2)
CONTINUUM_VARIANTS = (("position_yoshida4", 0.5), ("position_yoshida4", 0.7),
                      ("blanes_moan4", 1.0), ("blanes_moan4", 1.25), ("blanes_moan4", 1.45),
                      ("blanes_moan4", 1.5))
"""(integrator, dt_safety) of the continuum accuracy study; the first is the default."""
ENERGY_KEYS = ("Ek_L", "Ep_L", "Et_L", "Ek_R", "Ep_R", "Et_R")


def wall_sections(chain, sim_or_snap, wl, wr):
    """Kinetic, potential and total energy of the left and right sections, J."""
    ek, ep, et = grain_energy(chain, sim_or_snap.u, sim_or_snap.v, wl, wr)
    s = chain.section
    out = {}
    for name, side in (("L", 0), ("R", 1)):
        m = s == side
        out[f"Ek_{name}"] = float(ek[m].sum())
        out[f"Ep_{name}"] = float(ep[m].sum())
        out[f"Et_{name}"] = float(et[m].sum())
    return out


def front_position(v, lo):
    p = leading_pulse(v, lo=lo, threshold=0.3)
    return p.position if p is not None else math.nan


def full_run(case: str, integrator: str, fraction: float, *, dt_scale: float = 1.0,
             threads=None) -> dict:
    """One Fig. 5 run; returns timings and observables."""
    ar, ak = theory.PAPER_POINTS[case]
    ch = Chain.two_section(N_LEFT, N_RIGHT, ar, ak, DELTA0)
    t0 = time.perf_counter()
    ini = cut_wave(ch, CENTRE, cache_dir=CACHE)
    t_wave = time.perf_counter() - t0
    dt = default_dt(ini.chain, ini.u, ini.v, ini.wall_left, ini.wall_right,
                    fraction=fraction) * dt_scale
    rec = Recording(maxima=True, snapshots=[WaveAt(FRONT_1)], monitor_every=2000)
    sim = ini.simulation(dt=dt, integrator=integrator, record=rec, threads=threads)
    t0 = time.perf_counter()
    info = sim.run(until=WaveAt(FRONT_2), progress=False)
    wall = time.perf_counter() - t0
    s1 = sim.record.snapshot(f"wave_at={FRONT_1}")
    s2 = sim.record.snapshot(f"wave_at={FRONT_2}")
    speed = ((front_position(s2.v, N_LEFT) - front_position(s1.v, N_LEFT))
             / (s2.t - s1.t))
    return {"case": case, "integrator": integrator, "dt": dt, "steps": sim.steps,
            "t": sim.t, "wall": wall, "wave_s": t_wave, "stopped_by": info.stopped_by,
            "drift": sim.energy_drift, "speed": speed,
            "evals": sim.steps * get_integrator(integrator).stages,
            **wall_sections(ch, s2, sim.wall_left, sim.wall_right)}


def print_full(rows: list[dict]) -> None:
    print(f"{'case':>4} {'method':>13} {'dt (s)':>9} {'steps':>8} {'wall (s)':>8} "
          f"{'Ek_L':>11} {'Ep_L':>11} {'Ek_R':>11} {'Ep_R':>11} {'Et_L+Et_R':>11} "
          f"{'front (grains/s)':>16} {'drift':>8}")
    for r in rows:
        print(f"{r['case']:>4} {r['integrator']:>13} {r['dt']:>9.3e} {r['steps']:>8} "
              f"{r['wall']:>8.1f} {r['Ek_L']:>11.5e} {r['Ep_L']:>11.5e} {r['Ek_R']:>11.5e} "
              f"{r['Ep_R']:>11.5e} {r['Et_L'] + r['Et_R']:>11.5e} {r['speed']:>16.7e} "
              f"{r['drift']:>8.1e}")


# ---------------------------------------------------------------------------- dt study
D_STUDY = 1_000
STUDY = {"verlet": (0.008, 0.004, 0.002, 0.001),
         "yoshida4": (0.048, 0.024, 0.012),
         "blanes_moan4": (0.192, 0.096, 0.048, 0.024)}


GAP_CASE = "a0"
"""Study-only case: Fig. 3a's δ0 = 0 heavy-light chain (α_ρ = 0.2), gaps open at the
interface (the Hertz force is only C¹ at r = 0): 400 | 800 grains, the settled δ0 = 0
wave at grain 100, T = 3.5 ms (the front ~400 grains past the interface)."""


def study_setup(case: str):
    if case == GAP_CASE:
        ch = Chain.two_section(400, 800, alpha_rho=0.2)
        return ch, cut_wave(ch, 100, cache_dir=CACHE), 3.5e-3
    ar, ak = theory.PAPER_POINTS[case]
    probe = Chain.two_section(2, 2, ar, ak, DELTA0)
    c0 = np.sqrt(1.5 * probe.k[1:4] * np.sqrt(probe.delta0[1:4]) / probe.mass[:3])
    c_l, c_r = float(c0[0]), float(c0[2])  # grains/s, long-wave sound speeds
    n_left = 300 + int(1.2 * D_STUDY * c_l / c_r) + 400
    ch = Chain.two_section(n_left, D_STUDY + 300, ar, ak, DELTA0)
    ini = cut_wave(ch, n_left - 300, cache_dir=CACHE)
    t_end = 300 / c_l + D_STUDY / c_r
    return ch, ini, t_end


def study_run(ch, ini, t_end, integrator, dt_target):
    n = 4 * max(1, round(t_end / dt_target / 4))
    dt = t_end / n
    rec = Recording(maxima=False, snapshots=[AtTime(0.75 * t_end)], monitor_every=10**9)
    sim = ini.simulation(dt=dt, integrator=integrator, record=rec, drift_tolerance=1.0)
    t0 = time.perf_counter()
    sim.run(max_steps=n, progress=False)
    wall = time.perf_counter() - t0
    s1 = sim.record.snapshots[0]
    n_left = int(np.sum(ch.section == 0))
    speed = ((front_position(sim.v, n_left) - front_position(s1.v, n_left))
             / (sim.t - s1.t))
    return {"dt": dt, "steps": n, "wall": wall, "speed": speed,
            "evals": n * get_integrator(integrator).stages,
            **wall_sections(ch, sim, sim.wall_left, sim.wall_right)}


def dt_study(cases: list[str]) -> list[str]:
    keys = (*ENERGY_KEYS, "speed")
    verdicts = []
    for case in cases:
        ch, ini, t_end = study_setup(case)
        dt0 = default_dt(ini.chain, ini.u, ini.v, fraction=1.0)  # 2π/ω_max, s
        ref = study_run(ch, ini, t_end, "verlet", 1e-9)
        what = ("δ0 = 0, gaps open (Fig. 3a set-up)" if case == GAP_CASE else
                f"front followed {D_STUDY} grains")
        print(f"\n## case {case}: reduced chain {ch.n} grains (interface at "
              f"{int(np.sum(ch.section == 0))}), {what}, "
              f"T = {t_end:.6e} s; reference: verlet, dt = {ref['dt']:.3e} s, "
              f"{ref['steps']} steps, {ref['wall']:.1f} s wall")
        print("   reference " + "  ".join(f"{k}={ref[k]:.9e}" for k in keys))
        # energies that matter (> 1e-3 of the total) for the order fit
        e_tot = abs(ref["Et_L"] + ref["Et_R"])
        sig = [k for k in ENERGY_KEYS if abs(ref[k]) > 1e-3 * e_tot]
        print(f"   {'method':>13} {'f':>6} {'dt (s)':>9} {'evals':>8} " + " ".join(
            f"{'d' + k:>9}" for k in keys) + "  (relative differences to the reference)")
        for method, fractions in STUDY.items():
            errs = []
            dts = []
            for f in fractions:
                r = study_run(ch, ini, t_end, method, f * dt0)
                rel = [abs(r[k] - ref[k]) / abs(ref[k]) for k in keys]
                errs.append(max(x for k, x in zip(keys, rel, strict=False) if k in sig))
                dts.append(r["dt"])
                mark = " <- production" if (method, f) == PRODUCTION else ""
                print(f"   {method:>13} {f:>6.3f} {r['dt']:>9.3e} {r['evals']:>8} "
                      + " ".join(f"{x:>9.1e}" for x in rel) + mark)
                if (method, f) == PRODUCTION and case != GAP_CASE:
                    ok = max(rel) < REL_4_DIGITS
                    verdicts.append(f"case {case}: production ({method}, dt = {r['dt']:.3e} s) "
                                    f"vs dt = 1e-9 s: max relative difference {max(rel):.1e} "
                                    f"-> {'agrees' if ok else 'DOES NOT agree'} to 4 "
                                    f"significant digits")
            e = np.array(errs)
            good = e > 1e-9  # well above the reference's own error
            if good.sum() >= 2:
                order = np.polyfit(np.log(np.array(dts)[good]), np.log(e[good]), 1)[0]
                print(f"   {'':>13} fitted order of the largest relative difference of "
                      f"{', '.join(sig)}: {order:.2f}")
    return verdicts


def continuum_accuracy(cases: list[str]) -> list[str]:
    """The continuum of Fig. 5 per time-step variant against a converged reference."""
    from hertzchain.reproduce import fig5
    from hertzchain.reproduce.common import Context
    from theory.splitting import get_splitting

    out = Path(tempfile.mkdtemp(prefix="fig5-continuum-"))
    ctx = Context(out=out, mode="quick", progress=False, checkpoint_interval=None)
    verdicts = []
    print(f"{'case':>4} {'integrator':>18} {'safety':>6} {'evals/(1/ω)':>11} "
          f"{'L2 vs ref':>9} {'cpu s':>7} {'cpu ratio':>9}")
    def one(case, method, safety):
        for f in (out / "runs").glob("*continuum*"):  # computed anew, not read back
            f.unlink()
        s = dict(fig5.QUICK, continuum_integrator=method, continuum_dt_safety=safety)
        t0 = time.process_time()
        res = fig5._case(ctx, case, s)
        return res.continuum.v, time.process_time() - t0

    for case in cases:
        fig5._case(ctx, case, fig5.QUICK)  # the discrete run, cached for the rest
        ref, _ = one(case, *CONTINUUM_REFERENCE)
        base = None
        for method, safety in CONTINUUM_VARIANTS:
            v, cpu = one(case, method, safety)
            base = cpu if base is None else base
            err = float(np.linalg.norm(v - ref) / np.linalg.norm(ref))
            cost = get_splitting(method).stages / (2 * safety)
            print(f"{case:>4} {method:>18} {safety:>6g} {cost:>11.2f} {err:>9.2e} "
                  f"{cpu:>7.2f} {cpu / base:>9.2f}", flush=True)
            if (method, safety) == (fig5.FULL.get("continuum_integrator"),
                                    fig5.FULL.get("continuum_dt_safety")):
                verdicts.append(f"case {case}: --full's continuum ({method} at dt_safety "
                                f"{safety:g}) within {err:.1e} (L2) of the reference")
    return verdicts


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--full", action="store_true", help="the timed full runs")
    p.add_argument("--dt-study", action="store_true", help="the reduced-chain dt study")
    p.add_argument("--richardson", action="store_true", help="full runs again at dt/2")
    p.add_argument("--verlet", action="store_true",
                   help="also time velocity Verlet at its default dt")
    p.add_argument("--cases", default=CASES, help="of abcd (and a0, the δ0 = 0 gap case, "
                   "in the dt study)")
    p.add_argument("--threads", type=int, default=None)
    p.add_argument("--continuum", action="store_true",
                   help="the continuum's time-step accuracy (quick geometry)")
    a = p.parse_args(argv)
    cases = re.findall(r"a0|[abcd]", a.cases)
    full_cases = [c for c in cases if c != GAP_CASE]
    if not (a.full or a.dt_study or a.richardson or a.continuum):
        a.full = a.dt_study = a.richardson = True
    print(f"# load average {os.getloadavg()[0]:.2f}; settled-wave cache {CACHE}; "
          f"CPU {cpu_name()}")
    verdicts = []
    if a.continuum:
        print("# continuum of Fig. 5 (quick geometry): time-step accuracy and CPU time")
        verdicts += continuum_accuracy(full_cases)
    if a.dt_study:
        print("# dt study (reduced chain; module docstring)")
        verdicts += dt_study(cases + ([GAP_CASE] if a.cases == CASES else []))
    if (a.full or a.richardson) and full_cases:
        method, fraction = PRODUCTION
        print(f"\n# full Fig. 5 runs: {N_LEFT + N_RIGHT} grains, {method} at "
              f"f = {fraction} (dt = f·2π/ω_max), threads = {a.threads or 'auto'}")
        rows = []
        for case in full_cases:
            r = full_run(case, method, fraction, threads=a.threads)
            rows.append(r)
            print(f"case {case}: {r['wall']:.1f} s wall ({r['steps']} steps, "
                  f"{r['evals']} force evaluations; settled wave {r['wave_s']:.1f} s, "
                  f"cached after the first), stopped by {r['stopped_by']}", flush=True)
        print_full(rows)
        if a.verlet:
            vrows = [full_run(case, "verlet", 0.002, threads=a.threads)
                     for case in full_cases]
            print("\n# velocity Verlet at its default dt (f = 0.002), for comparison")
            print_full(vrows)
        if a.richardson:
            print("\n# Richardson check: production dt vs dt/2 (relative differences; "
                  "error ≈ 16/15 × difference for a 4th-order method)")
            keys = (*ENERGY_KEYS, "speed")
            print(f"{'case':>4} " + " ".join(f"{'d' + k:>9}" for k in keys))
            for r in rows:
                h = full_run(r["case"], method, fraction, dt_scale=0.5, threads=a.threads)
                rel = [abs(r[k] - h[k]) / abs(h[k]) for k in keys]
                print(f"{r['case']:>4} " + " ".join(f"{x:>9.1e}" for x in rel))
                ok = max(rel) * 16 / 15 < REL_4_DIGITS
                verdicts.append(f"case {r['case']}: full run, dt vs dt/2: max relative "
                                f"difference {max(rel):.1e} -> "
                                f"{'4 significant digits' if ok else 'NOT 4 digits'}")
    if verdicts:
        print("\n# verdicts")
        for v in verdicts:
            print(v)
    print(f"# load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
