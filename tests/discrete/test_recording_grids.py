"""``Record.energy`` (:class:`discrete.recording.EnergyGrid`): one owner of the energy grid.

The grid's values are those of the rows stacked, bit for bit, in every case.  A run
reserves its rows up to t_end in one segment per kind (also when cut into segments by
``hertzchain.checkpoint.run_segmented``) and the kernel writes each chunk's rows straight
into it (``block``/``commit``), so the grid is read as views, no copy; rows past the
reservation (a run bounded by an event only) or appended with ``extend`` (a file read
back) go to further segments, joined once, on the first read, each segment dropped as
soon as it is copied (a grid never held twice); later reads are views of the
joined arrays, read-only.  The memory check uses tracemalloc
(NumPy reports its buffers to it): reading the grids of a summarised run
(``energy_grids``, ``arrays``, which ``discrete.save`` writes) allocates nothing of a
grid's size.
"""

import tracemalloc

import numpy as np
import pytest

import theory
from discrete.recording import EnergyGrid, Record
from hertzchain.scenario import parse_scenario


def _record(blocks):
    """A record whose grid is made of per-kind (rows, n) blocks, as a run's."""
    rec = Record(series_grains=np.zeros(0, np.int64))
    t = 0.0
    for k, p in blocks:
        rec.energy.extend(t + np.arange(k.shape[0]), k, p)
        t += k.shape[0]
    return rec


def _same(a, b):
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def _blocks(rng, sizes, n):
    return [(rng.standard_normal((r, n)), rng.standard_normal((r, n))) for r in sizes]


def test_blocks_are_joined_to_the_rows_stacked():
    rng = np.random.default_rng(1)
    blocks = _blocks(rng, (3, 1, 5), 7)
    rec = _record(blocks)
    assert len(rec.energy) == 9 and rec.energy.consistent()
    t, ek, ep = rec.energy_grids()
    assert _same(ek, np.concatenate([k for k, _ in blocks]))
    assert _same(ep, np.concatenate([p for _, p in blocks]))
    assert _same(t, np.concatenate([np.arange(3.0), 3 + np.arange(1.0), 4 + np.arange(5.0)]))
    arr = rec.arrays()
    assert _same(t, arr["energy_t"]) and _same(ek, arr["energy_kinetic"])
    assert not ek.flags.writeable and not ep.flags.writeable
    with pytest.raises(ValueError):
        ek[0, 0] = 1.0  # (a write raises instead of changing the record)
    # joined once: the second read is a view of the same array, and of arrays()'s
    t2, ek2, ep2 = rec.energy_grids()
    assert np.shares_memory(ek, ek2) and np.shares_memory(ep, ep2)
    assert np.shares_memory(ek, rec.energy_kinetic) and np.shares_memory(t, t2)
    assert np.shares_memory(arr["energy_potential"], ep) and arr["series"].flags.writeable
    # rows appended after a read: joined again, the values of all rows stacked
    k, p = rng.standard_normal((2, 7)), rng.standard_normal((2, 7))
    rec.energy.extend([9.0, 10.0], k, p)
    _, ek3, ep3 = rec.energy_grids()
    assert _same(ek3, np.concatenate([ek, k])) and _same(ep3, np.concatenate([ep, p]))


def test_a_single_block_is_the_grid_without_a_copy():
    k, p = np.arange(12.0).reshape(3, 4), -np.arange(12.0).reshape(3, 4)
    rec = _record([(k, p)])
    _, ek, ep = rec.energy_grids()
    assert np.shares_memory(ek, k) and np.shares_memory(ep, p) and k.flags.writeable


class _Tracked(np.ndarray):
    """A block that reports, when it is freed, which rows of the joined array are filled."""

    log: list = []
    joined: list = []

    def __del__(self):
        if getattr(self, "tracked", False) and _Tracked.joined:  # (not its views)
            filled = int(np.count_nonzero(~np.isnan(_Tracked.joined[0][:, 0])))
            _Tracked.log.append(filled)


def test_joining_frees_each_block_before_copying_the_next(monkeypatch):
    # The record drops each kind's block as soon as it is copied: while the grid is
    # joined the memory holds the new array plus the blocks not yet copied, never both
    # whole (the old interleaved blocks: ~3 kinds of the grid at once).
    rng = np.random.default_rng(3)
    rec = Record(series_grains=np.zeros(0, np.int64))
    for i in range(4):
        k = rng.standard_normal((5, 3)).view(_Tracked)
        k.tracked = True
        rec.energy.extend(10.0 * i + np.arange(5), k, rng.standard_normal((5, 3)))
    del k
    empty = np.empty

    def nan_empty(shape, *a, **kw):  # (the joined array starts NaN: its filled rows seen)
        out = empty(shape, *a, **kw)
        out.fill(np.nan)
        if len(np.shape(out)) == 2 and out.shape[0] == 20 and not _Tracked.joined:
            _Tracked.joined.append(out)
        return out

    monkeypatch.setattr(np, "empty", nan_empty)
    _Tracked.log.clear()
    _Tracked.joined.clear()
    rec.energy.grids()
    monkeypatch.undo()
    # block i freed when rows 0..5(i+1) were filled, before the next block's copy
    assert _Tracked.log == [5, 10, 15, 20]
    _Tracked.joined.clear()


def test_bad_blocks_are_refused_naming_the_parameter():
    g = EnergyGrid()
    with pytest.raises(ValueError, match="kinetic"):
        g.extend([0.0, 1.0], np.zeros((3, 4)), np.zeros((3, 4)))
    with pytest.raises(ValueError, match="potential"):
        g.extend([0.0], np.zeros((1, 4)), np.zeros((1, 5)))
    with pytest.raises(ValueError, match="kinetic"):
        g.extend([0.0], np.zeros((1, 4), np.float32), np.zeros((1, 4)))
    g.extend([0.0], np.zeros((1, 4)), np.zeros((1, 4)))
    with pytest.raises(ValueError, match="columns"):
        g.extend([1.0], np.zeros((1, 5)), np.zeros((1, 5)))
    assert len(g) == 1


def test_empty_record():
    rec = Record(series_grains=np.zeros(0, np.int64))
    t, ek, ep = rec.energy_grids()
    assert t.shape == (0,) and ek.shape == (0, 0) and ep.shape == (0, 0)
    assert len(rec.energy) == 0 and rec.energy.consistent()


def test_a_summarised_run_s_grids_are_read_without_allocating_them_again():
    # A small Table 2-like run (point N): after the runner's summary, reading the grids
    # allocates less than 1 % of one grid (views), where stacking them allocates both.
    from hertzchain.runner import build_simulation, summarise

    ar, ak = theory.PAPER_POINTS["N"]
    sc = parse_scenario({
        "name": "grids", "chain": {"delta0_over_d": 1e-3, "sections": [
            {"n": 150}, {"n": 200, "alpha_rho": ar, "alpha_kn": ak}]},
        "initial": {"kind": "exact_wave", "center": 75, "velocity_max": 0.0822},
        "run": {"t_end": 3e-4}, "record": {"energy_every": 2}})
    chain, _, sim = build_simulation(sc)
    sim.run(3e-4)
    # the run reserved its rows (t_end) and the kernel wrote them there: one segment,
    # read without a copy, by the summary too
    assert len(sim.record.energy._k) == 1
    storage = sim.record.energy._k[0]
    summarise(chain, sim)
    assert sim.record.energy._k[0] is storage
    assert np.shares_memory(sim.record.energy_kinetic, storage)
    grid_bytes = sim.record.energy_kinetic.nbytes
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
    copied, again = peak(lambda: [np.stack(list(g)) for g in (ek, ep)])
    assert copied >= 2 * grid_bytes and _same(again[0], ek)


@pytest.mark.parametrize("move_bytes", [0, 2**20])
def test_blocks_past_the_reservation_grow_the_storage_and_keep_every_row(monkeypatch,
                                                                       move_bytes):
    # block/commit as the run uses them: a reservation, then rows past it (a run bounded
    # by an event only) in new segments (move_bytes 0: joined on the read; the default:
    # these few rows moved into each new segment); the values bit for bit.
    import discrete.recording as R

    rng = np.random.default_rng(4)
    g = EnergyGrid()
    g.append(0.0, np.ones(3), -np.ones(3))  # (the row a Simulation takes at its start)
    g.reserve(4, 3)
    assert len(g._k) == 1 and len(g) == 1  # (the first row moved into the reservation)
    monkeypatch.setattr(R, "SMALL_MOVE_BYTES", move_bytes)
    want_k, want_p, want_t = [np.ones((1, 3))], [-np.ones((1, 3))], [np.zeros(1)]
    for rows, used in ((3, 2), (5, 5), (2, 0), (9, 7)):
        k, p = g.block(rows, 3)
        assert k.shape == (rows, 3) and p.shape == (rows, 3)
        k[:used], p[:used] = rng.standard_normal((2, used, 3))
        t = len(g) + np.arange(used, dtype=float)
        g.commit(t)
        want_k.append(k[:used].copy())
        want_p.append(p[:used].copy())
        want_t.append(t)
    assert (len(g._k) > 1) == (move_bytes == 0) and len(g) == 15
    t, ek, ep = g.grids()
    assert len(g._k) == 1
    assert _same(ek, np.concatenate(want_k)) and _same(ep, np.concatenate(want_p))
    assert _same(t, np.concatenate(want_t))
    with pytest.raises(ValueError, match="cols"):
        g.block(1, 4)
    with pytest.raises(ValueError, match="t: no block is open"):
        g.commit(np.zeros(1))  # (each block commits once: rows only through block)


@pytest.mark.parametrize("every,coarsen", [(7, 1), (1000, 3)])
def test_a_segmented_run_stores_its_grid_in_one_segment_bit_for_bit(every, coarsen):
    # hertzchain.checkpoint.run_segmented (what reproduce's points run through, with
    # checkpointing on) calls run() once per segment of restart_period steps, passing
    # t_end to each: the first call reserves the rows up to t_end, the later ones find
    # them; each chunk asks for exactly the rows the kernel writes.  Segments of 800
    # steps (monitor_every) are not multiples of every=7, so chunks start off a multiple
    # (the requests used to overflow the reservation).  every=1000 > the segment:
    # segments with no row at all.  One segment, and bit for bit the uninterrupted run.
    from discrete import Chain, Recording, Section, Simulation
    from discrete.initial import impact
    from hertzchain.checkpoint import run_segmented

    mat = theory.PAPER_MATERIAL
    chain = Chain.from_sections([Section(200, 5e-3, mat)], delta0=1e-3 * 5e-3,
                                left_wall="paper", right_wall="paper")
    state = impact(chain, 1.0)
    sims = []
    for _ in range(2):
        rec = Recording(energy_every=every, energy_coarsen=coarsen, monitor_every=800)
        sims.append(Simulation(chain, state.u, state.v, record=rec))
    whole, seg = sims
    t_end = whole.t0 + 6100.5 * whole.dt
    whole.run(t_end, progress=False)
    run_segmented(seg, t_end=t_end, signals=False)
    assert seg.steps == whole.steps == 6101 and seg.restart_period == 800
    assert len(seg.record.energy) == 1 + seg.steps // every
    for sim in (seg, whole):
        assert len(sim.record.energy._k) == 1  # (one segment: read without a copy)
        storage = sim.record.energy._k[0]
        assert storage.shape[0] == len(sim.record.energy)  # (reserved exactly)
        assert np.shares_memory(sim.record.energy_kinetic, storage)
    for a, b in zip(seg.record.energy_grids(), whole.record.energy_grids(), strict=True):
        assert _same(a, b)
    assert _same(seg.u, whole.u) and _same(seg.v, whole.v)


def test_an_open_block_refuses_every_other_change_and_a_read():
    g = EnergyGrid()
    g.append(0.0, np.ones(3), -np.ones(3))
    k, p = g.block(2, 3)
    for what, call in (("grids", g.grids), ("append", lambda: g.append(1.0, k[0], p[0])),
                       ("extend", lambda: g.extend([1.0], np.ones((1, 3)), np.ones((1, 3)))),
                       ("reserve", lambda: g.reserve(5, 3)), ("block", lambda: g.block(1, 3))):
        with pytest.raises(RuntimeError, match=f"EnergyGrid.{what}: a block of 2 rows"):
            call()
    k[:1], p[:1] = 2.0, -2.0
    g.commit([1.0])
    t, ek, ep = g.grids()
    assert _same(t, np.array([0.0, 1.0])) and _same(ek, np.array([[1.0] * 3, [2.0] * 3]))
    with pytest.raises(ValueError, match="t: no block is open"):
        g.commit([2.0])  # (committed once)


def test_commit_refuses_rows_of_a_storage_it_did_not_hand_out():
    g = EnergyGrid()
    g.reserve(2, 3)
    g.block(1, 3)
    g._k[-1] = np.zeros((2, 3))  # (as if the storage had been replaced meanwhile)
    with pytest.raises(ValueError, match="storage changed"):
        g.commit([0.0])


def test_bad_rows_and_rows_of_unequal_kinds_are_refused_naming_the_parameter():
    g = EnergyGrid()
    for bad in (-1, 1.5, True):
        with pytest.raises(ValueError, match="rows must be an integer >= 0"):
            g.block(bad, 3)
    k, p = g.block(0, 3)  # (a chunk with no row: an empty block)
    assert k.shape == (0, 3) and p.shape == (0, 3)
    g.commit(())
    for k, p in ((np.ones(3), np.ones(4)), (np.ones((1, 3)), np.ones((1, 3))),
                 (1.0, 2.0)):
        with pytest.raises(ValueError, match="kinetic and potential must be 1-D"):
            g.append(0.0, k, p)
    assert len(g) == 0


def test_extend_keeps_c_contiguous_segments():
    k = np.arange(12.0).reshape(4, 3).T  # (Fortran order)
    g = EnergyGrid()
    g.extend(np.arange(3.0), k, k.copy())
    assert g._k[0].flags.c_contiguous and _same(g.grids()[1], np.ascontiguousarray(k))
    c = np.ones((2, 3))
    g2 = EnergyGrid()
    g2.extend([0.0, 1.0], c, c)
    assert g2._k[0] is c  # (C-contiguous: kept, no copy)


def test_a_file_with_a_grid_of_the_wrong_width_fails_on_load_naming_the_dataset(tmp_path):
    pytest.importorskip("h5py")
    from discrete import Chain, Recording, Section, Simulation, load, save
    from discrete.initial import impact

    chain = Chain.from_sections([Section(20, 5e-3, theory.PAPER_MATERIAL)],
                                delta0=1e-3 * 5e-3, left_wall="paper", right_wall="paper")
    state = impact(chain, 1.0)
    sim = Simulation(chain, state.u, state.v,
                     record=Recording(energy_every=5, energy_coarsen=3))
    sim.run(max_steps=20, progress=False)
    assert sim.record.energy.columns == 7  # ceil(20 / 3)
    path = save(tmp_path / "a.h5", sim)
    assert load(path).record.energy.columns == 7
    # a file written (and sealed) with a grid one column short: refused on load
    t, ek, ep = sim.record.energy_grids()
    bad = EnergyGrid()
    bad.extend(t, ek[:, :6].copy(), ep[:, :6].copy())
    sim.record.energy = bad
    path = save(tmp_path / "b.h5", sim)
    with pytest.raises(ValueError, match=r"record/energy_kinetic.*ceil\(n / energy_coarsen\) = 7"):
        load(path)
