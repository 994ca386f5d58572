"""HDF5 round trip."""

import json

import h5py
import numpy as np

from discrete import Chain, Recording, WaveAt
from discrete.initial import impact
from discrete.io import load, save


def test_save_load_roundtrip_and_continue(tmp_path):
    ch = Chain.two_section(150, 150, alpha_kn=5.0, delta0_over_d=1e-4)
    rec = Recording(snapshots=[100, 2e-4, WaveAt(250)], series_grains=[149, 150],
                    series_every=10, energy_every=2000, energy_coarsen=5,
                    refined_maxima=True)
    sim = impact(ch).simulation(record=rec)
    sim.run(until=WaveAt(120), progress=False)
    path = save(tmp_path / "run.h5", sim)
    assert not list(tmp_path.glob("*.tmp"))
    with h5py.File(path) as f:
        for key in ("package_version", "dt", "steps", "energy_drift", "units", "chain_params"):
            assert key in f.attrs
        assert f["state/u"].attrs["units"] == "m"
        assert json.loads(f.attrs["chain_params"])["alpha_kn"] == 5.0
        assert f["record/series"].compression == "gzip"
    back = load(path)
    assert back.steps == sim.steps and back.dt == sim.dt and back.t == sim.t
    assert np.array_equal(back.u, sim.u) and np.array_equal(back.v, sim.v)
    assert np.array_equal(back.chain.k, ch.k) and back.chain.params == ch.params
    a, b = sim.record.arrays(), back.record.arrays()
    for key in a:
        assert np.array_equal(a[key], b[key]), key
    assert [s.label for s in back.record.snapshots] == [s.label for s in sim.record.snapshots]
    # the refined maxima and the peak state behind them (NaN: pending grains)
    assert np.isnan(sim.record.peak_state[0]).any()
    for name in ("vmax_refined", "vmax_time", "peak_state"):
        assert np.array_equal(getattr(back.record, name), getattr(sim.record, name),
                              equal_nan=True), name
    # continuing the loaded run reproduces continuing the original bit for bit
    sim.run(until=WaveAt(250), progress=False)
    back.run(until=WaveAt(250), progress=False)
    assert back.steps == sim.steps
    assert np.array_equal(back.u, sim.u) and np.array_equal(back.record.vmax, sim.record.vmax)
    for name in ("vmax_refined", "vmax_time", "peak_state"):
        assert np.array_equal(getattr(back.record, name), getattr(sim.record, name),
                              equal_nan=True), name
