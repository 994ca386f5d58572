"""The numba kernel against the NumPy reference; active window; reversibility."""

import numba
import numpy as np
import pytest

from discrete import Chain, Recording, Simulation
from discrete import kernels as K
from discrete import reference as R
from discrete.initial import exact_wave
from discrete.integrators import INTEGRATORS


def _gappy_run(random_composite, rng, steps, **kw):
    ch = random_composite(rng)
    v = rng.normal(0.0, 0.3, ch.n)  # 0.3 m/s random kicks: many contacts open and close
    sim = Simulation(ch, v=v, record=Recording(series_grains=list(range(ch.n))), **kw)
    sim.run(max_steps=steps, progress=False)
    return ch, v, sim


def test_kernel_matches_numpy_reference(rng, make_composite):
    # 1e4 steps on a random composite chain with gaps opening and closing.  The two
    # codes differ in rounding only (relative vs absolute forces, r*sqrt(r) vs r**1.5),
    # ~1e-16 per step; 1e-12 leaves room for the growth of round-off over 1e4 steps
    # (measured: 2.4e-14 on v).
    ch, v, sim = _gappy_run(make_composite, rng, 10_000, active_window=False)
    u_ref, v_ref = R.run(ch, np.zeros(ch.n), v, sim.dt, 10_000)
    assert np.max(np.abs(sim.u - u_ref)) <= 1e-12 * np.max(np.abs(u_ref))
    assert np.max(np.abs(sim.v - v_ref)) <= 1e-12 * np.max(np.abs(v_ref))
    overlaps = sim.record.arrays()["series"][:, :, 2]
    assert (overlaps <= 0).mean() > 0.05  # the test really exercises [.]_+


def test_rest_in_equilibrium_has_exactly_zero_acceleration(rng, make_composite):
    ch = make_composite(rng, delta0=3e-6)
    u = np.full(ch.n, 1.3e-6)  # uniform shift with the walls: every contact at δ0 exactly
    a = np.full(ch.n, np.nan)
    kern = K.make_kernels()
    p = K.kernel_params(kern.law)
    f0 = kern.static_forces(ch.k, ch.delta0, p)
    assert np.array_equal(f0, ch.f0)  # the chain's k δ0^{3/2} is the kernels' arithmetic
    con = (1 / ch.mass, ch.k, ch.delta0, f0, *K.chain_runs(1 / ch.mass, ch.k, ch.delta0, f0))
    kern.accelerations(u, np.zeros(ch.n), a, con, p, 1.3e-6, 1.3e-6, 0, ch.n - 1)
    assert np.all(a == 0.0)


@pytest.mark.parametrize("integrator", sorted(INTEGRATORS))
@pytest.mark.parametrize("delta0, exact", [(0.0, False), (5e-6, False), (5e-6, True)])
def test_active_window_bitwise_identical(delta0, exact, integrator):
    # A pulse in the middle of a long chain (or an exact solitary wave, with the grains
    # behind it and the left wall shifted), a watched event and all recording on:
    # windowed and full integration must agree bit for bit (no tolerance).
    ch = Chain.two_section(300, 300, alpha_kn=0.2, delta0_over_d=delta0 / 5e-3)
    u = np.zeros(ch.n)
    v = np.zeros(ch.n)
    wl = 0.0
    v[100] = 1.0
    v[101] = 0.5
    if exact:
        ini = exact_wave(ch, 150, velocity_max=0.3)
        u, v, wl = ini.u, ini.v, ini.wall_left
    rec = dict(series_grains=[50, 100, 299, 300], series_every=7, energy_every=500,
               monitor_every=1000, snapshots=[250, 3e-4])
    runs = []
    for window in (True, False):
        sim = Simulation(ch, u, v, dt=2e-7, wall_left=wl, record=Recording(**rec),
                         active_window=window, chunk=333, integrator=integrator)
        sim.run(t_end=1e-3, progress=False)
        runs.append(sim)
    a, b = runs
    assert a.steps == b.steps
    assert np.array_equal(a.u, b.u) and np.array_equal(a.v, b.v)
    assert np.array_equal(a.record.vmax, b.record.vmax)
    assert np.array_equal(a.record.umax, b.record.umax)
    ra, rb = a.record.arrays(), b.record.arrays()
    assert np.array_equal(ra["series"], rb["series"])
    assert [(s.label, s.step) for s in a.record.snapshots] == [
        (s.label, s.step) for s in b.record.snapshots]
    assert np.array_equal(ra["energy_kinetic"], rb["energy_kinetic"])
    lo, hi = a.window
    assert 0 < hi - lo < ch.n - 1  # the window really was smaller than the chain


def test_time_reversibility():
    # Verlet is time-reversible: forward n steps, flip v, n steps back recovers the
    # initial state up to round-off.  60,000 steps take an impact pulse through a
    # soft-hard interface (grain 150) with ~80 open gaps; measured 3.6e-13 (u, relative
    # to the largest displacement) and 2.5e-14 m/s (v).  Round-off grows chaotically
    # after reflections (3e-11 at 80,000 steps, 4e-8 at 120,000); tolerance 1e-8.
    ch = Chain.two_section(150, 150, alpha_kn=5.0)
    v0 = np.zeros(ch.n)
    v0[0] = 1.0
    sim = Simulation(ch, v=v0)
    sim.run(max_steps=60_000, progress=False)
    assert sim.window[1] > 200 and np.sum(sim.overlaps()[1:-1] < 0) > 20
    umax = np.max(np.abs(sim.u))
    back = Simulation(ch, sim.u, -sim.v, dt=sim.dt)
    back.run(max_steps=60_000, progress=False)
    assert np.max(np.abs(back.u)) <= 1e-8 * umax
    assert np.max(np.abs(back.v + v0)) <= 1e-8 * np.max(np.abs(v0))


@numba.njit
def _raised_loop(g, x):
    """``_raised`` in a loop over arrays, as the passes use it (vectorised by LLVM)."""
    for i in range(g.size):
        g[i] = K._raised(g[i], x[i])


def test_raised_is_the_conditional_running_max_bit_for_bit():
    """``_raised`` (the running max stored at every grain) = ``if x > g: g = x``.

    Bit for bit, signed zeros, infinities and NaN included (a NaN x must not raise g; a
    NaN g stays), scalar and in a vectorised loop over every pair (13 x 13 = 169 pairs:
    the vector body and its remainder; the loop's compiled code is the passes' ``maxpd``
    where LLVM vectorises it).  Compared as int64 bit patterns, so -0.0 against 0.0
    fails.
    """
    vals = [0.0, -0.0, 1.0, -1.0, 5e-324, -5e-324, 1e308, np.inf, -np.inf, 0.1, -0.1,
            np.nan, -np.nan]
    gs = np.array([g for g in vals for _ in vals])
    xs = np.array([x for _ in vals for x in vals])
    want = np.array([x if x > g else g for g, x in zip(gs, xs, strict=True)])
    scalar = np.array([K._raised(g, x) for g, x in zip(gs, xs, strict=True)])
    looped = gs.copy()
    _raised_loop(looped, xs)
    for got in (scalar, looped):
        bad = np.flatnonzero(got.view(np.int64) != want.view(np.int64))
        assert bad.size == 0, [(gs[i], xs[i], got[i]) for i in bad]


def test_overlap_maxima_are_the_running_max_of_the_sampled_overlaps(rng, make_composite):
    # The fused passes raise the overlap maxima (strain_maxima) with ``_raised`` at every
    # contact and step; the plain NumPy maximum over the initial overlaps and the
    # overlaps sampled every step (the series, the same arithmetic d0 + (u_left - u)) must
    # be the same bits, gaps opening and closing (0.3 m/s random kicks).
    ch = make_composite(rng)
    v = rng.normal(0.0, 0.3, ch.n)
    sim = Simulation(ch, v=v, record=Recording(
        series_grains=list(range(ch.n)), strain_maxima=True, monitor_every=10**6))
    first = sim.overlaps().copy()
    sim.run(max_steps=3000, progress=False)
    s = sim.record.arrays()["series"]
    sampled = np.concatenate([s[:, :, 2], s[:, -1:, 3]], axis=1)  # contacts 0..N
    want = np.maximum(first, sampled.max(axis=0))
    assert np.array_equal(sim.record.overlap_max, want)
    assert (sampled <= 0).mean() > 0.05  # gaps: the clip [r]_+ is exercised


def test_overlap_maxima_blocked_and_threaded_bitwise(monkeypatch):
    # The same overlap maxima from the temporally blocked kernel on 2 threads (small
    # tiles and thresholds, as tests/discrete/test_parallel.py) as step by step: the
    # tiles run the same fused loops on disjoint grains.
    from discrete import simulation as S

    monkeypatch.setattr(S, "TILE_GRAINS", 256)
    monkeypatch.setattr(S, "SERIAL_BLOCK_MIN_GRAINS", 0)
    ch = Chain.two_section(1500, 500, alpha_rho=0.2, delta0_over_d=1e-3)
    v = np.random.default_rng(1).normal(0.0, 1e-2, ch.n)
    runs = []
    for threads, block in ((1, 0), (2, 64)):
        sim = Simulation(ch, v=v.copy(), threads=threads, record=Recording(
            strain_maxima=True, monitor_every=10**6))
        sim.block_steps = block
        sim.min_parallel = 0
        sim.run(max_steps=1000, progress=False)
        runs.append(sim)
    a, b = runs
    assert np.array_equal(a.u, b.u) and np.array_equal(a.v, b.v)
    assert np.array_equal(a.record.overlap_max, b.record.overlap_max)
    assert np.array_equal(a.record.vmax, b.record.vmax)
    assert np.any(a.record.overlap_max > a.overlaps())  # (the maxima moved)


def test_special_grains_are_numpys_unique_and_searchsorted():
    # The chunk's set-up finds its special grains without numba's sort and search
    # overloads (compile time): the same integers as np.unique / np.searchsorted, with
    # repeated, unsorted and empty inputs.
    rng = np.random.default_rng(7)
    cases = [(np.zeros(0, np.int64), np.zeros(0, np.int64)),
             (np.array([5], np.int64), np.zeros(0, np.int64)),
             (np.zeros(0, np.int64), np.array([3, 3, 1], np.int64))]
    cases += [(rng.integers(0, 20, rng.integers(0, 6)), rng.integers(0, 20, rng.integers(0, 9)))
              for _ in range(50)]
    for watch, series in cases:
        watch, series = watch.astype(np.int64), series.astype(np.int64)
        sp_w = K._sorted_distinct(watch, watch)
        sp_ws = K._sorted_distinct(watch, series)
        np.testing.assert_array_equal(sp_w, np.unique(watch))
        np.testing.assert_array_equal(sp_ws, np.unique(np.concatenate((watch, series))))
        np.testing.assert_array_equal(K._positions(sp_ws, series),
                                      np.searchsorted(sp_ws, series))
        np.testing.assert_array_equal(K._positions(sp_w, watch), np.searchsorted(sp_w, watch))
