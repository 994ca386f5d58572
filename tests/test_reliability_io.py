"""Atomic outputs and clear errors for damaged HDF5 input.

Damage applied to a real run file: truncated to half its size, overwritten with
garbage, a dataset removed, one byte flipped inside a compressed data chunk (caught by
the Fletcher-32 checksum).  Every reader — ``discrete.io.load``, ``hertzchain info``,
``hertzchain plot`` — must raise ``ValueError`` naming the file (the CLI: exit code 2
and the file name on stderr), never an h5py traceback.  (Resuming from a damaged
checkpoint: ``tests/test_reliability_checkpoint.py``.)
"""

from __future__ import annotations

import os
import stat

import h5py
import numpy as np
import pytest

import discrete
from discrete.io import load, save
from hertzchain.cli import main
from hertzchain.files import describe, plot_file
from hertzchain.runner import run_scenario
from hertzchain.scenario import parse_scenario
from theory import integrity

SCENARIO = {"name": "io", "chain": {"delta0_over_d": 1e-3, "sections": [
    {"n": 150}, {"n": 200, "alpha_rho": 0.5, "alpha_kn": 2.0}]},
    "initial": {"kind": "exact_wave", "center": 75, "velocity_max": 0.0822},
    "run": {"t_end": 3e-4}, "record": {"snapshot_times": [1e-4], "time_series_grains": [10]}}


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    path = tmp_path_factory.mktemp("io") / "run.h5"
    run_scenario(parse_scenario(SCENARIO), out=path)
    return path


def _flip_in_chunk(path, dataset: str) -> None:
    with h5py.File(path, "r") as f:
        info = f[dataset].id.get_chunk_info(0)
    with open(path, "r+b") as fh:
        fh.seek(info.byte_offset + info.size // 2)
        b = fh.read(1)
        fh.seek(info.byte_offset + info.size // 2)
        fh.write(bytes([b[0] ^ 0x5A]))


def _damage(src, dst, how: str) -> None:
    dst.write_bytes(src.read_bytes())
    if how == "truncate":
        with dst.open("r+b") as fh:
            fh.truncate(dst.stat().st_size // 2)
    elif how == "garbage":
        dst.write_bytes(np.random.default_rng(1).bytes(20_000))
    elif how == "remove_dataset":
        with h5py.File(dst, "a") as f:
            del f["record/energy_kinetic"]
    elif how == "flip_byte":
        _flip_in_chunk(dst, "record/series")


DAMAGE = ["truncate", "garbage", "remove_dataset", "flip_byte"]


@pytest.mark.parametrize("how", DAMAGE)
def test_load_names_the_file(how, result, tmp_path):
    bad = tmp_path / f"{how}.h5"
    _damage(result, bad, how)
    with pytest.raises(ValueError) as err:
        load(bad)
    assert str(bad) in str(err.value)


@pytest.mark.parametrize("how", ["truncate", "garbage", "remove_dataset"])
def test_info_names_the_file(how, result, tmp_path, capsys):
    bad = tmp_path / f"{how}.h5"
    _damage(result, bad, how)
    with pytest.raises(ValueError, match=str(bad)):
        describe(bad)
    assert main(["info", str(bad)]) == 2
    assert f"hertzchain: error: {bad}" in capsys.readouterr().err


@pytest.mark.parametrize("how", DAMAGE)
def test_plot_names_the_file(how, result, tmp_path, capsys):
    bad = tmp_path / f"{how}.h5"
    _damage(result, bad, how)
    assert main(["plot", str(bad), "--out", str(tmp_path / "x.png")]) == 2
    assert f"hertzchain: error: {bad}" in capsys.readouterr().err
    assert not (tmp_path / "x.png").exists()


def test_undamaged_file_reads_and_plots(result, tmp_path):
    # control for the tests above: the same readers succeed on the intact file
    assert "summary" in describe(result)
    assert load(result).steps > 0
    png = plot_file(result, tmp_path / "ok.png")
    assert png.stat().st_size > 1000
    assert stat.S_IMODE(png.stat().st_mode) == 0o666 & ~_umask()
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def test_missing_and_foreign_files(tmp_path):
    with pytest.raises(ValueError, match="no such file"):
        load(tmp_path / "none.h5")
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as f:  # another program's file: cannot be verified
        f.attrs["format"] = "something else"
    with pytest.raises(ValueError, match=r"other.h5: no integrity seal, so its content "
                                         r"cannot be verified: not a hertzchain result "
                                         r"file \(hertzchain.discrete/1\)"):
        load(other)
    with integrity.sealed_hdf5(other) as f:  # sealed, but not a discrete run
        f.attrs["format"] = "something else"
    with pytest.raises(ValueError, match=r"other.h5 is not a hertzchain.discrete/1 file"):
        load(other)


def test_save_is_atomic_and_keeps_the_old_file(result, tmp_path, monkeypatch):
    # A writer that fails midway leaves the previous file untouched and no temporary.
    target = tmp_path / "run.h5"
    target.write_bytes(result.read_bytes())
    before = target.read_bytes()
    sim = load(result)
    import discrete.io as dio

    real = dio._ds
    calls = [0]

    def failing(*args, **kwargs):
        calls[0] += 1
        if calls[0] == 8:
            raise OSError("disk full (simulated)")
        return real(*args, **kwargs)

    monkeypatch.setattr(dio, "_ds", failing)
    with pytest.raises(OSError, match="disk full"):
        save(target, sim)
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.h5"]
    monkeypatch.setattr(dio, "_ds", real)
    save(target, sim)
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~_umask()  # not mkstemp's 0600


def test_failed_run_writes_no_result_file(tmp_path):
    # a run that fails validation creates nothing at --out
    bad = parse_scenario({**SCENARIO, "run": {"t_end": 3e-4, "dt": 1.0}})
    with pytest.raises(ValueError):
        run_scenario(bad, out=tmp_path / "r.h5", checkpoint_interval=0.0)
    assert list(tmp_path.iterdir()) == []


def test_sweep_results_reader_names_the_file(tmp_path):
    from hertzchain.sweep.spec import load_sweep_spec, shipped_sweeps
    from hertzchain.sweep.store import read_results, write_table

    spec = load_sweep_spec(shipped_sweeps()["tiny"])
    path = write_table(tmp_path / "results.h5", spec, spec.points(), {})
    with path.open("r+b") as fh:
        fh.truncate(path.stat().st_size // 2)
    with pytest.raises(ValueError, match=str(path)):
        read_results(path)


def test_loaded_simulation_continues_bit_for_bit(result, tmp_path):
    # discrete.io round trip of a run with the checksummed, compressed layout
    sim = load(result)
    save(tmp_path / "copy.h5", sim, compress=False)
    back = load(tmp_path / "copy.h5")
    assert sim.u.tobytes() == back.u.tobytes() and sim.a.tobytes() == back.a.tobytes()
    # the initial state's expected overlaps (instability messages) survive a reload
    assert back.time_step.delta_expected.tobytes() == sim.time_step.delta_expected.tobytes()
    assert back.dt_default == sim.dt_default
    t_end = sim.t + 5e-5
    sim.run(t_end, progress=False)
    back.run(t_end, progress=False)
    assert sim.u.tobytes() == back.u.tobytes() and sim.v.tobytes() == back.v.tobytes()
    assert isinstance(back, discrete.Simulation)


@pytest.mark.parametrize("integrator", ["yoshida4", "blanes_moan4"])
def test_integrator_is_carried_by_save_and_load(integrator, tmp_path):
    import inspect

    if "integrator" not in inspect.signature(discrete.Simulation).parameters:
        pytest.skip("Simulation has no integrator option yet")
    ch = discrete.Chain.two_section(60, 60, alpha_kn=2.0)  # sonic vacuum: gaps, compact wave
    init = discrete.exact_wave(ch, 30.0, velocity_max=0.3)
    sim = init.simulation(integrator=integrator, record=discrete.Recording(monitor_every=100))
    sim.run(max_steps=300, progress=False)
    back = load(save(tmp_path / "r.h5", sim))
    assert back.integrator == integrator
    sim.run(max_steps=300, progress=False)
    back.run(max_steps=300, progress=False)
    assert sim.u.tobytes() == back.u.tobytes() and sim.v.tobytes() == back.v.tobytes()
