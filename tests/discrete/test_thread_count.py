"""numba's thread count is read only where the blocked kernel can run (discrete.Simulation).

Reading it (``numba.get_num_threads``) starts numba's threading layer, tens of ms of a
short run's start-up.  The plain kernel has no parallel region, so a chain that always
runs it — below ``min_parallel`` grains, or on one thread below
``SERIAL_BLOCK_MIN_GRAINS`` — neither reads nor sets the count; ``threads=None`` is
resolved to numba's count when first needed.  Results do not depend on it
(tests/discrete/test_parallel.py); here: which kernel runs, the count resolved, and a
run on one thread bitwise equal to one with numba's count.
"""

import numba
import numpy as np

import discrete.simulation as S
from discrete import Chain, Recording
from discrete.initial import impact


def _sim(n, threads=None):
    """A δ0 = 0 impact on ``n`` equal grains (two equal sections)."""
    return impact(Chain.two_section(n // 2, n - n // 2)).simulation(
        threads=threads, record=Recording(refined_maxima=True))


def test_small_chain_runs_the_plain_kernel_whatever_the_threads():
    for threads in (None, 1, min(2, numba.config.NUMBA_NUM_THREADS)):
        sim = _sim(100, threads=threads)
        assert sim._plain_only()
        assert sim.kernel is sim.kernels.run_steps


def test_large_chain_on_one_thread_runs_the_plain_kernel(monkeypatch):
    # a chain above min_parallel: plain on one thread, blockable on several
    sim = _sim(200, threads=1)
    sim.min_parallel = 100
    assert sim._plain_only() and sim.kernel is sim.kernels.run_steps
    auto = _sim(200)
    auto.min_parallel = 100
    assert not auto._plain_only()
    monkeypatch.setattr(S, "SERIAL_BLOCK_MIN_GRAINS", 150)
    assert not sim._plain_only()  # (serial blocking from this size)


def test_threads_none_is_numbas_count_when_read():
    sim = _sim(100)
    assert sim._threads is None  # (not read at construction)
    assert sim.threads == numba.get_num_threads()


def test_plain_run_bitwise_equal_on_one_thread_and_numbas_count():
    a, b = _sim(300, threads=1), _sim(300)
    a.run(max_steps=3000, progress=False)
    b.run(max_steps=3000, progress=False)
    assert a.steps == b.steps == 3000
    for name in ("u", "v", "a"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert np.array_equal(a.record.vmax, b.record.vmax)
