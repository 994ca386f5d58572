"""Cost of the continuum solvers on a 1,000-d chain, and the ratio to the discrete solver.

Scenario (the same for every solver): a uniform chain of 1,000 paper grains; the
paper's solitary wave starts at grain 100 and travels 800 grain diameters.
* precompressed, δ0/d = 1e-3, v_max = 0.0822 m/s: BoussinesqPDE (regularised Eq. 4,
  orders 2 and 4), KdVPDE (co-moving frame, RK4) and the discrete solver (exact discrete
  wave, default dt);
* sonic vacuum, δ0 = 0, v_max = 0.68 m/s: NesterenkoPDE (regularised Eq. 7) and the
  discrete solver.
Times exclude numba compilation (a short warm-up run first).  Prints one line per solver
and the continuum/discrete wall-time ratios.  Usage: ``python benchmarks/continuum.py``.
"""

import sys
import time
from pathlib import Path

# this file is named like the package it measures: keep its folder off the import path
_here = Path(__file__).resolve().parent
sys.path[:] = [p for p in sys.path if Path(p or ".").resolve() != _here]

import numpy as np  # noqa: E402

import theory  # noqa: E402
from continuum import (  # noqa: E402
    BoussinesqPDE,
    KdVPDE,
    Medium,
    NesterenkoPDE,
    compacton,
    compacton_parameters,
    run,
    solitary_wave,
    solitary_wave_parameters,
)

N_GRAINS, START, DIST, NODES = 1000, 100.0, 800.0, 5
D = theory.PAPER_DIAMETER


def timed(fn, warm):
    warm()
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def boussinesq(order):
    med = Medium.uniform(N_GRAINS, 1e-3 * D)
    pde = BoussinesqPDE(med, NODES)
    state = solitary_wave(pde, START, velocity_max=0.0822)
    t_end = DIST / solitary_wave_parameters(pde, START, velocity_max=0.0822)["speed"]
    dt = pde.stable_dt(state)
    sec, res = timed(lambda: run(pde, state, t_end, dt=dt, order=order, interval=t_end),
                     lambda: run(pde, state, 10 * dt, dt=dt, order=order, interval=10 * dt))
    return sec, int(round(t_end / dt)), res.energy_drift


def kdv():
    med = Medium.uniform(N_GRAINS, 1e-3 * D)
    pde = KdVPDE.for_medium(med)
    pde.frame_speed = pde.speed
    amp = solitary_wave_parameters(BoussinesqPDE(med, 1), START,
                                   velocity_max=0.0822)["amplitude"]
    grid = KdVPDE.grid(N_GRAINS, NODES)
    s0 = pde.soliton(grid, amp, START)
    t_end = DIST / pde.soliton_speed(amp)
    dt = pde.stable_dt(s0)
    kw = dict(solver="runge-kutta", adaptive=False, tracker=None, backend="numba")
    sec, _ = timed(lambda: pde.solve(s0, t_range=t_end, dt=dt, **kw),
                   lambda: pde.solve(s0, t_range=10 * dt, dt=dt, **kw))
    return sec, int(round(t_end / dt)), float("nan")


def nesterenko():
    med = Medium.uniform(N_GRAINS, 0.0)
    par0 = compacton_parameters(NesterenkoPDE(med, 1, delta_floor=0.0), velocity_max=0.68)
    pde = NesterenkoPDE(med, NODES, delta_floor=1e-2 * par0["amplitude"])
    state = compacton(pde, START, velocity_max=0.68)
    t_end = DIST / par0["speed"]
    dt = pde.stable_dt(state)
    sec, res = timed(lambda: run(pde, state, t_end, dt=dt, interval=t_end),
                     lambda: run(pde, state, 10 * dt, dt=dt, interval=10 * dt))
    return sec, int(round(t_end / dt)), res.energy_drift


def discrete(delta0_over_d, vmax, speed):
    import discrete as dm

    chain = dm.Chain.two_section(N_GRAINS, 0, 1.0, 1.0, delta0_over_d)
    init = dm.exact_wave(chain, START, velocity_max=vmax)
    t_end = DIST / speed

    def go(t):
        sim = init.simulation()
        info = sim.run(t, progress=False)
        return sim, info

    sec, (sim, info) = timed(lambda: go(t_end), lambda: go(t_end / 100))
    return sec, int(sim.steps), float(info.energy_drift)


def main():
    rows = {}
    rows["boussinesq (Eq. 4, Verlet-2)"] = boussinesq(2)
    rows["boussinesq (Eq. 4, Yoshida-4)"] = boussinesq(4)
    rows["kdv (RK4, co-moving)"] = kdv()
    rows["nesterenko (Eq. 7, Verlet-2)"] = nesterenko()
    med = Medium.uniform(N_GRAINS, 1e-3 * D)
    v_pre = solitary_wave_parameters(BoussinesqPDE(med, 1), START,
                                     velocity_max=0.0822)["speed"]
    v_vac = compacton_parameters(NesterenkoPDE(Medium.uniform(N_GRAINS, 0.0), 1,
                                               delta_floor=0.0), velocity_max=0.68)["speed"]
    try:
        rows["discrete (δ0/d = 1e-3)"] = discrete(1e-3, 0.0822, v_pre)
        rows["discrete (δ0 = 0)"] = discrete(0.0, 0.68, v_vac)
    except ImportError:  # pragma: no cover - discrete package absent
        pass
    print(f"{N_GRAINS} grains, wave travels {DIST:g} d; continuum: {NODES} nodes per grain")
    print(f"{'solver':34s} {'wall s':>8s} {'steps':>9s} {'energy drift':>13s}")
    for name, (sec, steps, drift) in rows.items():
        print(f"{name:34s} {sec:8.2f} {steps:9d} {drift:13.1e}")
    pre = rows.get("discrete (δ0/d = 1e-3)")
    vac = rows.get("discrete (δ0 = 0)")
    if pre and vac:
        print("ratios continuum / discrete (wall time):")
        for name, (sec, _, _) in rows.items():
            if name.startswith("discrete"):
                continue
            ref = vac if "nesterenko" in name else pre
            print(f"  {name:32s} {sec / ref[0]:8.2f}")
    return rows


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
