"""``Record.energy_grids``: the recorded energy grid without a second copy (issue 13).

The grid's values are those of the rows stacked, bit for bit, in every case; a kind whose
rows are the consecutive rows of one array (after ``hertzchain.runner`` stacked them) is
that array, read-only; rows of several blocks (as the run appends them), or not in
order, are stacked into a new array.  The memory check uses tracemalloc (NumPy reports
its buffers to it): reading the stacked grids of a finished run (``energy_grids``,
``arrays``, which ``discrete.save`` writes) allocates nothing of a grid's size.
"""

import tracemalloc

import numpy as np

import theory
from discrete.recording import Record
from hertzchain.scenario import parse_scenario


def _record(blocks):
    """A record whose rows are views of interleaved (rows, 2, n) blocks, as a run's."""
    rec = Record(series_grains=np.zeros(0, np.int64))
    t = 0.0
    for b in blocks:
        rec.energy_kinetic.extend(b[:, 0])
        rec.energy_potential.extend(b[:, 1])
        rec.energy_t.extend((t + np.arange(b.shape[0])).tolist())
        t += b.shape[0]
    return rec


def _same(a, b):
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def test_rows_of_blocks_are_stacked_to_the_values_of_arrays():
    rng = np.random.default_rng(1)
    rec = _record([rng.standard_normal((n, 2, 7)) for n in (3, 1, 5)])
    t, ek, ep = rec.energy_grids()
    arr = rec.arrays()
    assert _same(t, arr["energy_t"]) and _same(ek, arr["energy_kinetic"])
    assert _same(ep, arr["energy_potential"])
    assert not ek.flags.writeable and not ep.flags.writeable
    assert not np.shares_memory(ek, rec.energy_kinetic[0])  # (a new array)


def test_stacked_rows_are_returned_without_a_copy():
    rng = np.random.default_rng(2)
    rec = _record([rng.standard_normal((4, 2, 6)), rng.standard_normal((2, 2, 6))])
    grids = {}
    for key in ("energy_kinetic", "energy_potential"):  # as runner._stacked_grid does
        rows = getattr(rec, key)
        grids[key] = np.stack(rows)
        rows[:] = list(grids[key])
    t, ek, ep = rec.energy_grids()
    assert np.shares_memory(ek, grids["energy_kinetic"])
    assert np.shares_memory(ep, grids["energy_potential"])
    assert _same(ek, grids["energy_kinetic"]) and _same(ep, grids["energy_potential"])
    assert not ek.flags.writeable and not ep.flags.writeable
    assert grids["energy_kinetic"].flags.writeable  # (the record's own array unchanged)
    arr = rec.arrays()  # the same views there; the other fields new arrays
    assert np.shares_memory(arr["energy_kinetic"], grids["energy_kinetic"])
    assert not arr["energy_potential"].flags.writeable and arr["series"].flags.writeable


def test_rows_of_one_array_out_of_order_or_partial_are_copied():
    g = np.arange(24.0).reshape(4, 6)
    for rows in ([g[1], g[0], g[2], g[3]], [g[0], g[1], g[2]], [g[0], g[2], g[1], g[3]]):
        rec = Record(series_grains=np.zeros(0, np.int64))
        rec.energy_kinetic = list(rows)
        rec.energy_potential = list(rows)
        rec.energy_t = list(range(len(rows)))
        _, ek, _ = rec.energy_grids()
        assert _same(ek, np.stack(rows)) and not np.shares_memory(ek, g)


def test_empty_record():
    t, ek, ep = Record(series_grains=np.zeros(0, np.int64)).energy_grids()
    assert t.shape == (0,) and ek.shape == (0, 0) and ep.shape == (0, 0)


def test_a_summarised_run_s_grids_are_read_without_allocating_them_again():
    # A small Table 2-like run (point N): after the runner's summary, reading the grids
    # allocates less than 1 % of one grid (views), where arrays() allocates both again.
    from hertzchain.runner import build_simulation, summarise

    ar, ak = theory.PAPER_POINTS["N"]
    sc = parse_scenario({
        "name": "grids", "chain": {"delta0_over_d": 1e-3, "sections": [
            {"n": 150}, {"n": 200, "alpha_rho": ar, "alpha_kn": ak}]},
        "initial": {"kind": "exact_wave", "center": 75, "velocity_max": 0.0822},
        "run": {"t_end": 3e-4}, "record": {"energy_every": 2}})
    chain, _, sim = build_simulation(sc)
    sim.run(3e-4)
    summarise(chain, sim)
    grid_bytes = len(sim.record.energy_kinetic) * len(sim.record.energy_kinetic[0]) * 8
    assert grid_bytes > 1_000_000  # (large enough for the 1 % bound to mean something)

    def peak(fn):
        tracemalloc.start()
        try:
            out = fn()
            return tracemalloc.get_traced_memory()[1], out
        finally:
            tracemalloc.stop()

    used, (_, ek, ep) = peak(sim.record.energy_grids)
    assert used < 0.01 * grid_bytes
    used, arr = peak(sim.record.arrays)  # (what discrete.save writes)
    assert used < 0.01 * grid_bytes
    assert _same(ek, arr["energy_kinetic"]) and _same(ep, arr["energy_potential"])
    # (the bound can fail: stacking the rows again is seen, both grids)
    copied, again = peak(lambda: [np.stack(r) for r in (sim.record.energy_kinetic,
                                                        sim.record.energy_potential)])
    assert copied >= 2 * grid_bytes and _same(again[0], ek)
