"""Energy-grid rows taken inside the kernel are bitwise those of chunks ending there.

``run_chunk`` closes a step at every multiple of ``energy_every`` like a chunk's last
step and opens the next with its kick (:mod:`discrete.kernels`), so one long run must
give bit for bit the state and the energy grid of the same run cut into chunks at
every row (where the rows are taken by :class:`discrete.Simulation` in Python, the path
vertical chains keep), with and without temporal blocking and threads.
"""

import numpy as np
import pytest

import theory
from discrete import Chain, Recording, Section, Simulation
from discrete.initial import impact

MAT = theory.PAPER_MATERIAL


def _runs(n, every, coarsen, steps, **kwargs):
    chain = Chain.from_sections([Section(n, 5e-3, MAT)], delta0=1e-3 * 5e-3,
                                left_wall="paper", right_wall="paper")
    if n < 1000:
        u, v = impact(chain, 1.0).u, impact(chain, 1.0).v
    else:  # every grain moves: the window is the whole chain (blocks, threads)
        u, v = np.zeros(n), 1e-3 * np.random.default_rng(1).standard_normal(n)
    out = []
    for cut in (None, every):
        rec = Recording(energy_every=every, energy_coarsen=coarsen)
        sim = Simulation(chain, u, v, record=rec, **kwargs)
        if cut is None:
            sim.run(max_steps=steps, progress=False)
        else:
            for _ in range(steps // cut):
                sim.run(max_steps=cut, progress=False)
        out.append(sim)
    return out


def _same(a: Simulation, b: Simulation) -> None:
    ra, rb = a.record.arrays(), b.record.arrays()
    assert a.steps == b.steps
    np.testing.assert_array_equal(a.u, b.u)
    np.testing.assert_array_equal(a.v, b.v)
    for key in ("energy_t", "energy_kinetic", "energy_potential"):
        assert ra[key].shape == rb[key].shape, key
        np.testing.assert_array_equal(ra[key], rb[key], err_msg=key)
    np.testing.assert_array_equal(a.record.vmax, b.record.vmax)


@pytest.mark.parametrize("every,coarsen", [(7, 1), (13, 3)])
def test_rows_in_kernel_match_chunked_rows(every, coarsen):
    a, b = _runs(300, every, coarsen, 91 * every)
    assert len(a.record.energy_t) == 92  # the initial row and one per multiple
    _same(a, b)
    # the rows are the energies: kinetic + potential is conserved (to O(dt²))
    e = a.record.arrays()["energy_kinetic"].sum(1) + a.record.arrays()[
        "energy_potential"].sum(1)
    assert np.max(np.abs(e / e[0] - 1)) < 1e-4


def test_rows_in_kernel_with_blocks_and_threads():
    """A 24,000-grain chain: the blocked, threaded kernel ends its blocks at the rows."""
    a, b = _runs(24_000, 40, 8, 40 * 20, threads=2)
    assert a.block_steps > 0 and a.kernel is a.kernels.run_blocked
    _same(a, b)
