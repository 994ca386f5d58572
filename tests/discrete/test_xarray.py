"""xarray export (the optional ``xarray`` extra): values, dimensions, units; the message
when xarray is missing."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest

from discrete import Chain, Recording, Section, WaveAt
from discrete.initial import impact
from discrete.io import XARRAY_EXTRA, load, save, to_xarray
from discrete.waves import TRAIN_FIELDS, Train, split_train
from theory import PAPER_MATERIAL


@pytest.fixture(scope="module")
def sim():
    # a 4-mass striker on 60 grains, every kind of record: snapshots, series, sensors,
    # wall forces, a coarsened energy grid, refined maxima
    ch = Chain.from_sections([Section(60, 5e-3, PAPER_MATERIAL)], right_wall=None)
    rec = Recording(snapshots=[1e-5, WaveAt(30)], series_grains=[5, 20], series_every=7,
                    sensors=[10], wall_forces=True, energy_every=50, energy_coarsen=4,
                    refined_maxima=True)
    s = impact(ch, 1.0, striker_mass=4 * ch.mass[0]).simulation(record=rec)
    s.run(until=WaveAt(45), progress=False)
    return s


def test_to_xarray_holds_the_record_with_named_dims_and_units(sim):
    pytest.importorskip("xarray")
    ds = sim.to_xarray()
    n = sim.chain.n
    # grains counted from 0, the striker is grain 0 (docs/guide/cli.md, 'Grain indices')
    np.testing.assert_array_equal(ds["grain"], np.arange(n))
    assert ds["section"].sel(grain=0) == -1 and ds.sizes["contact"] == n + 1
    assert ds["v"].dims == ("grain",) and ds["overlap"].dims == ("contact",)
    # values bit for bit
    a = sim.record.arrays()
    np.testing.assert_array_equal(ds["u"], sim.u)
    np.testing.assert_array_equal(ds["v"].values, sim.v)
    np.testing.assert_array_equal(ds["overlap"], sim.overlaps())
    np.testing.assert_array_equal(ds["k"], sim.chain.k)
    np.testing.assert_array_equal(ds["vmax"], sim.record.vmax)
    np.testing.assert_array_equal(ds["vmax_refined"], sim.record.vmax_refined)
    np.testing.assert_array_equal(ds["time"], a["series_t"])
    np.testing.assert_array_equal(ds["series_v"].sel(series_grain=20), a["series"][:, 1, 1])
    np.testing.assert_array_equal(ds["series_overlap_right"], a["series"][:, :, 3])
    np.testing.assert_array_equal(ds["sensor_force"].sel(sensor=10), a["sensor_force"][:, 0])
    np.testing.assert_array_equal(ds["wall_force"].sel(wall="left"), a["wall_force"][:, 0])
    np.testing.assert_array_equal(ds["energy_kinetic"], a["energy_kinetic"])
    np.testing.assert_array_equal(ds["energy_block"], np.arange(ds.sizes["energy_block"]) * 4)
    assert ds["energy_kinetic"].dims == ("energy_time", "energy_block")
    np.testing.assert_array_equal(ds["monitor_energy"], a["monitor_energy"])
    snaps = sim.record.snapshots
    assert list(ds["snapshot_label"].values) == [s.label for s in snaps]
    np.testing.assert_array_equal(ds["snapshot_v"].isel(snapshot=1), snaps[1].v)
    np.testing.assert_array_equal(ds["snapshot_time"], [s.t for s in snaps])
    # units and long names on every variable and coordinate (those of the HDF5 file)
    units = json.loads(ds.attrs["units"])
    assert ds["u"].attrs["units"] == units["u"] == "m"
    assert ds["v"].attrs["units"] == "m/s" and ds["k"].attrs["units"] == "N/m^(3/2)"
    assert ds["energy_kinetic"].attrs["units"] == "J" and ds["time"].attrs["units"] == "s"
    for name in list(ds.data_vars) + list(ds.coords):
        if name not in ("snapshot_label", "wall"):
            assert ds[name].attrs.get("units"), name
        assert ds[name].attrs.get("long_name"), name
    # the run's parameters
    assert ds.attrs["dt"] == sim.dt and ds.attrs["steps"] == sim.steps
    assert ds.attrs["t"] == sim.t and ds.attrs["integrator"] == "verlet"
    assert json.loads(ds.attrs["contact_law"]) == sim.law.to_dict()
    assert all(not isinstance(v, bool) for v in ds.attrs.values())  # netCDF-able


def test_to_xarray_of_a_loaded_run_and_its_train(sim, tmp_path):
    pytest.importorskip("xarray")
    train = Train(tuple(split_train(sim, threshold=0.05, lo=1)), sim.t, 0.05, 0.5, 1,
                  sim.chain.n)
    path = save(tmp_path / "run.h5", sim, train=train)
    ds = to_xarray(load(path), train=train)
    direct = to_xarray(sim)
    for name in direct.data_vars:
        np.testing.assert_array_equal(ds[name], direct[name], err_msg=name)
    assert ds.sizes["wave"] == len(train) >= 2
    arrays = train.arrays()
    for name, unit in TRAIN_FIELDS.items():
        np.testing.assert_array_equal(ds[f"train_{name}"], arrays[name])
        assert ds[f"train_{name}"].attrs["units"] == unit
    assert ds.attrs["train_threshold"] == 0.05 and ds.attrs["train_lo"] == 1


def test_without_xarray_the_error_names_the_extra(sim, monkeypatch):
    monkeypatch.setitem(sys.modules, "xarray", None)  # import xarray raises ImportError
    with pytest.raises(ImportError, match="hertzchain\\[xarray\\]") as info:
        sim.to_xarray()
    assert XARRAY_EXTRA in str(info.value)
