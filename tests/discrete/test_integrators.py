"""The registered integrators (discrete.integrators), each against its NumPy step.

Dedalus style: every test is parametrised over the registry.  Each method must match
its plain-NumPy implementation, converge at its order on smooth problems, and be
time-reversible.
"""

import numpy as np
import pytest

from discrete import DT_FRACTION, Chain, Recording, Simulation
from discrete import integrators as I
from discrete.initial import exact_wave
from discrete.timestep import RTOL_CANDIDATES, default_fraction

NAMES = sorted(I.INTEGRATORS)


def test_registry():
    assert set(NAMES) == {"verlet", "yoshida4", "blanes_moan4"}
    for m in I.INTEGRATORS.values():
        assert len(m.kick) == m.stages + 1 and m.reference
        # consistency: the drifts and the kicks each add up to one step
        assert sum(m.drift) == pytest.approx(1.0, abs=1e-14)
        assert sum(m.kick) == pytest.approx(1.0, abs=1e-14)
        assert default_fraction(m) == pytest.approx(m.stages * DT_FRACTION)
    # integrator = "auto" (rtol) may pick every registered method, cheapest probed first
    assert sorted(RTOL_CANDIDATES) == NAMES
    stages = [I.get_integrator(n).stages for n in RTOL_CANDIDATES]
    assert stages == sorted(stages)
    with pytest.raises(ValueError, match="unknown integrator"):
        I.get_integrator("rk4")
    with pytest.raises(ValueError, match="unknown integrator"):
        Simulation(Chain.two_section(10, 0), dt=1e-8, integrator="leapfrog")


@pytest.mark.parametrize("name", NAMES)
def test_kernel_matches_numpy_step(name, rng, make_composite):
    # A random composite chain with 0.3 m/s kicks (gaps open and close), 1,000 steps at
    # the method's default dt (S × velocity Verlet's, S force evaluations per step):
    # kernel and NumPy differ by rounding only (relative vs absolute forces, r*sqrt(r)
    # vs r**1.5), amplified by the chaotic gap dynamics; 1e-12 as for velocity Verlet
    # (test_kernels.py).  Measured (u, v): 1.6e-16, 3.6e-16 (verlet); 2.5e-14, 6.5e-14
    # (yoshida4); 3.5e-15, 1.6e-14 (blanes_moan4).
    ch = make_composite(rng)
    v = rng.normal(0.0, 0.3, ch.n)
    sim = Simulation(ch, v=v, integrator=name, active_window=False,
                     record=Recording(series_grains=[0, 30, 59]))
    sim.run(max_steps=1000, progress=False)
    u_ref, v_ref = I.run(ch, np.zeros(ch.n), v, sim.dt, 1000, integrator=name)
    assert np.max(np.abs(sim.u - u_ref)) <= 1e-12 * np.max(np.abs(u_ref))
    assert np.max(np.abs(sim.v - v_ref)) <= 1e-12 * np.max(np.abs(v_ref))
    assert (sim.overlaps()[1:-1] < 0).any()
    # the synchronous velocities of the series grains are those of the state
    series = sim.record.arrays()["series"]
    assert np.array_equal(series[-1, :, 1], sim.v[[0, 30, 59]])


def _wave_error(name, delta0_over_d, divisions):
    """Velocity error after ~150 grains of an exact wave, vs the next finer run."""
    ch = Chain.two_section(400, 0, delta0_over_d=delta0_over_d)
    vmax = 0.05 if delta0_over_d else 0.5
    ini = exact_wave(ch, 100, velocity_max=vmax)
    t_end = 150 / ini.params["grain_rate"]
    m = I.get_integrator(name)
    base = ini.simulation().dt * m.stages * 4  # coarse: 4x the equal-cost step
    runs = []
    for div in divisions:
        n = int(np.ceil(t_end / (base / div)))
        sim = ini.simulation(dt=t_end / n, integrator=name, drift_tolerance=1.0)
        sim.run(max_steps=n, progress=False)
        runs.append(sim.v.copy())
    err = [np.max(np.abs(a - b)) for a, b in zip(runs[:-1], runs[1:], strict=True)]
    return np.array(err) / vmax


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("delta0_over_d", [1e-3, 0.0])
def test_order_of_convergence(name, delta0_over_d):
    # Fitted slope of log(error) vs log(dt) on the exact solitary wave, with and without
    # precompression (δ0 = 0: every contact closes from r = 0, where the Hertz force is
    # only C¹ — the 4th-order methods keep their order on this single closure per
    # contact; gap *openings* behind a scattered wave reduce it, measured in
    # benchmarks/fig5_full.py).  Measured slopes (δ0/d = 1e-3, 0): 2.00, 2.00 (verlet);
    # 4.00, 4.00 (yoshida4); 4.00, 4.02 (blanes_moan4).
    err = _wave_error(name, delta0_over_d, (1, 2, 4, 8))
    slope = np.polyfit(np.log([1.0, 0.5, 0.25]), np.log(err), 1)[0]
    order = I.get_integrator(name).order
    assert order - 0.3 < slope < order + 0.5, (err, slope)


@pytest.mark.parametrize("name", NAMES)
def test_time_reversibility(name):
    # Forward 10,000 steps through a soft-hard interface with open gaps, flip v, back:
    # the initial state to 1e-8 (as velocity Verlet, test_kernels.py).  Measured (u
    # relative, v in m/s): 9e-15, 1e-15 (verlet); 2e-12, 2e-13 (yoshida4); 3e-10, 2e-11
    # (blanes_moan4: 6x larger steps, 6 evaluations each, round-off amplified by gaps).
    ch = Chain.two_section(60, 60, alpha_kn=5.0)
    v0 = np.zeros(ch.n)
    v0[0] = 1.0
    sim = Simulation(ch, v=v0, integrator=name)
    sim.run(max_steps=10_000, progress=False)
    assert np.sum(sim.overlaps()[1:-1] < 0) > 5
    umax = np.max(np.abs(sim.u))
    back = Simulation(ch, sim.u, -sim.v, dt=sim.dt, integrator=name)
    back.run(max_steps=10_000, progress=False)
    assert np.max(np.abs(back.u)) <= 1e-8 * umax
    assert np.max(np.abs(back.v + v0)) <= 1e-8
