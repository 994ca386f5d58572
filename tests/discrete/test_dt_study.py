"""The time-step study behind the default dt (see discrete.simulation's docstring).

Velocity Verlet is second order: observables converge like dt².  The most dt-sensitive
observable found is v̄max/v0 of an impact on a precompressed chain; at the default
f = DT_FRACTION = 0.002 (dt ≈ 4.4e-8 s for the paper's grains) its error is ~1e-4
relative, so the paper's dt = 1e-9 s is ~40x smaller than 4-digit accuracy needs.
"""

import numpy as np

from discrete import Chain, WaveAt, default_dt
from discrete.initial import exact_wave, impact

FRACTIONS = (0.02, 0.01, 0.005, 0.0025)


def _vbar(fraction):
    ini = impact(Chain.two_section(1500, 0, delta0_over_d=1e-3))
    dt = default_dt(ini.chain, ini.u, ini.v, fraction=fraction)
    sim = ini.simulation(dt=dt, drift_tolerance=1.0)
    sim.run(until=WaveAt(1450), progress=False)
    return dt, sim.record.vmax[1000:1400].mean()


def test_vmax_converges_second_order():
    # Measured v̄max/v0 over grains 1000..1400 at f = 0.02 .. 0.0025: 0.085720, 0.085078,
    # 0.084918, 0.084878; successive differences fall by 4.03, 4.01 per halving: slope 2.
    # Richardson limit 0.084865: the default f = 0.002 is off by 1.0e-4 relative.
    dts, vals = zip(*[_vbar(f) for f in FRACTIONS], strict=True)
    diffs = np.abs(np.diff(vals))
    slope = np.polyfit(np.log(dts[1:]), np.log(diffs), 1)[0]
    assert 1.8 < slope < 2.2
    # Richardson limit and the error at the default fraction 0.002 (= f/1.25 of 0.0025)
    limit = vals[-1] - diffs[-1] / 3.0
    err_default = abs(vals[-1] - limit) * (0.002 / 0.0025) ** 2 / limit
    assert err_default < 2e-4
    assert dts[-1] * 0.002 / 0.0025 > 30 * 1e-9  # far above the paper's dt = 1e-9 s


def test_front_speed_converges_second_order():
    # Exact sonic-vacuum wave travelling ~500 grains: the position error of the wave
    # (v²-centroid vs the exact travelling wave) falls like dt²: relative speed errors
    # 1.12e-5, 2.81e-6, 7.0e-7 at 2, 1, 1/2 x the default dt (slope 2.00).
    ch = Chain.two_section(700, 0)
    ini = exact_wave(ch, 100, velocity_max=0.6816)
    from theory import discrete_solitary_wave
    w = discrete_solitary_wave(ch.k[1], ch.mass[0], ch.diameter[0], 0.0, velocity_max=0.6816)
    base = default_dt(ini.chain, ini.u, ini.v)
    i = np.arange(ch.n)
    errs = []
    for div in (0.5, 1, 2):
        sim = ini.simulation(dt=base / div)
        sim.run(t_end=500 / w.grain_rate, progress=False)
        exact = w.sample(ch.n, 100, sim.t).velocity
        shift = (i * sim.v**2).sum() / (sim.v**2).sum() - (i * exact**2).sum() / (exact**2).sum()
        errs.append(abs(shift) / (w.grain_rate * sim.t))
    slope = np.polyfit(np.log([2.0, 1.0, 0.5]), np.log(errs), 1)[0]
    assert 1.8 < slope < 2.2
    assert errs[1] < 1e-5
