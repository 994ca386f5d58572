"""Pieces, run tables, temporal blocking and threads: all bitwise identical to one pass.

The kernel may split a substep into pieces (special grains), read the grain constants
from a run table or from arrays, advance trapezoid tiles several steps at a time
(temporal blocking, rolled back when a block overshoots an event) and run the tiles of
a phase on several threads.  None of this may change a single bit of any result
(discrete.kernels module docstring); these tests compare whole runs with array_equal.
"""

import numba
import numpy as np
import pytest

import discrete.simulation as S
from discrete import AtTime, Chain, Recording, Simulation, WaveAt
from discrete import kernels as K
from discrete.initial import cut_wave, impact

THREADS = min(2, numba.config.NUMBA_NUM_THREADS)


def _same(a, b):
    ra, rb = a.record.arrays(), b.record.arrays()
    assert a.steps == b.steps
    for name in ("u", "v", "a"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert np.array_equal(a.record.vmax, b.record.vmax)
    assert np.array_equal(a.record.umax, b.record.umax)
    for name in ("vmax_refined", "vmax_time", "peak_state"):  # refined maxima, their state
        assert np.array_equal(getattr(a.record, name), getattr(b.record, name),
                              equal_nan=True), name
    assert np.any(a.record.vmax_refined > a.record.vmax)  # (every case records them)
    for name in ("series", "series_t", "monitor_energy", "monitor_shadow", "energy_kinetic"):
        assert np.array_equal(ra[name], rb[name]), name
    assert [(s.label, s.step) for s in a.record.snapshots] == [
        (s.label, s.step) for s in b.record.snapshots]
    for x, y in zip(a.record.snapshots, b.record.snapshots, strict=True):
        assert np.array_equal(x.u, y.u) and np.array_equal(x.v, y.v)


def _run(make, run_kw, *, block, threads, monkeypatch, tile=256):
    # small tiles and thresholds so that a 2,000-6,000-grain chain uses every mode
    monkeypatch.setattr(S, "TILE_GRAINS", tile)
    monkeypatch.setattr(S, "SERIAL_BLOCK_MIN_GRAINS", 0)
    sim = make(threads)
    sim.block_steps = block
    sim.min_parallel = 0
    sim.run(**run_kw, progress=False)
    return sim


CASES = {
    # precompressed cut wave into a light section; events before, at and after the
    # interface (inside the window: blocks overshoot them and are rolled back), a time
    # event, sampled series grains far from the wave (blocks allowed) and near it
    "cut_wave": (lambda th: cut_wave(Chain.two_section(1500, 1500, alpha_rho=0.2,
                                                       delta0_over_d=1e-3), 1200).simulation(
        threads=th, chunk=1000, record=Recording(
            snapshots=[1490, WaveAt(1510, threshold=1e-4), 2e-3], series_grains=[20, 2990],
            series_every=300, energy_every=5000, refined_maxima=True)),
        {"until": WaveAt(2400)}),
    # δ0 = 0 impact through a soft-hard interface: gaps open, u and v maxima move
    "gaps": (lambda th: impact(Chain.two_section(800, 1600, alpha_kn=5.0)).simulation(
        threads=th, record=Recording(snapshots=[900, AtTime(5e-4)], series_grains=[810],
                                     series_every=1, refined_maxima=True)),
        {"until": WaveAt(1500)}),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_blocked_and_threaded_runs_bitwise_identical(case, monkeypatch):
    make, run_kw = CASES[case]
    ref = _run(make, run_kw, block=0, threads=1, monkeypatch=monkeypatch)
    assert len(ref.record.snapshots) >= 2
    configs = [(64, 1), (13, 1)] + ([(64, THREADS), (16, THREADS)] if THREADS > 1 else [])
    for block, threads in configs:
        _same(ref, _run(make, run_kw, block=block, threads=threads, monkeypatch=monkeypatch))


@pytest.mark.skipif(THREADS < 2, reason="needs 2 numba threads")
def test_auto_threads_bitwise_identical(monkeypatch):
    # threads=None measures both modes while it runs and switches between them
    make, run_kw = CASES["cut_wave"]
    ref = _run(make, run_kw, block=64, threads=1, monkeypatch=monkeypatch)
    auto = _run(make, run_kw, block=64, threads=None, monkeypatch=monkeypatch)
    _same(ref, auto)
    assert auto._rates[1] is not None and auto._rates[THREADS] is not None


def test_run_table_matches_arrays():
    # The same chain through the run table (piecewise-constant constants as scalars)
    # and through the per-grain arrays.
    ch = Chain.two_section(700, 300, alpha_rho=5.0, alpha_kn=0.2, delta0_over_d=1e-3)
    rs, rc = K.chain_runs(1 / ch.mass, ch.k, ch.delta0, ch.f0)
    assert rs.size == 4  # left section, interface grain, right section (walls as sections)
    sims = []
    for runs in (True, False):
        sim = cut_wave(ch, 500).simulation(record=Recording(refined_maxima=True))
        if not runs:
            sim._runs = (np.zeros(0, np.int64), np.zeros((0, 4)))
        sim.run(until=WaveAt(900), progress=False)
        sims.append(sim)
    _same(*sims)


def test_chain_runs_table():
    mass = np.r_[np.full(50, 1.0), np.full(50, 2.0)]
    k = np.full(101, 3.0)
    inv_m = 1 / mass
    rs, rc = K.chain_runs(inv_m, k, np.zeros(101), np.zeros(101), min_length=10)
    assert rs.tolist() == [0, 50, 100]
    assert rc[:, 0].tolist() == [1.0, 0.5]
    # short runs (random chain): no table
    rng = np.random.default_rng(0)
    rs, rc = K.chain_runs(rng.uniform(1, 2, 100), k, np.zeros(101), np.zeros(101))
    assert rs.size == 0 and rc.shape == (0, 4)


@pytest.mark.parametrize("threads", [0, 99, 1.5])
def test_bad_threads(threads):
    with pytest.raises(ValueError, match="threads"):
        Simulation(Chain.two_section(10, 0), dt=1e-8, threads=threads)
