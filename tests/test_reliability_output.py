"""Output locations checked at start; a full disk named, never a crash.

Item 7: ``--out`` on a read-only place, a directory where a file is expected (or a file
where a directory is) was found only after the whole integration.  Now every command
checks it first (:func:`hertzchain.files.check_output`); if the final write still fails
the summary is printed and the checkpoint kept.

Item 6: a full disk made ``run``/``reproduce``/``sweep`` segfault (exit 139) after
h5py's "Exception ignored" flood: HDF5's close flushed again into the deleted temporary.
Fault injection two ways: ``OSError(ENOSPC)`` raised inside the writer (monkeypatch),
and a real write failure from the kernel in a subprocess whose file-size limit
(``RLIMIT_FSIZE``, ``EFBIG``) stops the HDF5 write half-way — the very path that
segfaulted (a small tmpfs is not available to unprivileged tests).
"""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import discrete
from hertzchain.cli import main
from hertzchain.files import check_output
from theory import integrity

SCENARIO = """\
[chain]
[[chain.sections]]
n = 60
[[chain.sections]]
n = 60
alpha_rho = 0.5
[initial]
kind = "impact"
[run]
t_end = 1e-3  # > 10,000 steps: more than one checkpoint segment
[record]
energy_every = 1
"""


@pytest.fixture
def scenario(tmp_path) -> Path:
    path = tmp_path / "small.toml"
    path.write_text(SCENARIO)
    return path


def _no_run(monkeypatch):
    """Make any integration fail the test: the check must come first."""
    import hertzchain.models

    def boom(*args, **kwargs):
        raise AssertionError("the run started before --out was checked")

    monkeypatch.setattr(hertzchain.models, "run", boom)
    monkeypatch.setattr(hertzchain.models, "_run_discrete", boom)


def _unwritable(tmp_path) -> Path:
    """A directory this process cannot create files in (a read-only place)."""
    if os.geteuid() == 0:  # root writes anywhere but on a read-only file system
        if not Path("/proc/self").exists():
            pytest.skip("no read-only place for root without /proc")
        return Path("/proc")
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    return ro


# -- item 7: checked at start ----------------------------------------------------------
def test_check_output_cases(tmp_path):
    (tmp_path / "a_file").write_text("x")
    assert check_output(tmp_path / "new" / "deeper" / "r.h5", "file")  # creatable
    assert check_output(tmp_path / "newdir", "dir")
    assert not (tmp_path / "new").exists() and not (tmp_path / "newdir").exists()
    with pytest.raises(IsADirectoryError, match="--out .* is a directory"):
        check_output(tmp_path, "file")
    with pytest.raises(NotADirectoryError, match="is a file; give a directory"):
        check_output(tmp_path / "a_file", "dir")
    with pytest.raises(NotADirectoryError, match="a_file is a file, not a directory"):
        check_output(tmp_path / "a_file" / "r.h5", "file")
    with pytest.raises(OSError, match="cannot be written"):
        check_output(_unwritable(tmp_path) / "r.h5", "file")
    assert not list(tmp_path.glob(".hertzchain-probe-*"))


@pytest.mark.parametrize("where", ["the scenario", "read-only", "under a file"])
def test_run_refuses_bad_out_before_integrating(where, scenario, tmp_path, monkeypatch,
                                                capsys):
    # (a directory is a valid --out since the one CLI grammar: docs/guide/cli.md)
    _no_run(monkeypatch)
    out = {"the scenario": scenario, "read-only": _unwritable(tmp_path) / "r.h5",
           "under a file": scenario / "r.h5"}[where]
    assert main(["run", str(scenario), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--out" in err and str(out) in err


@pytest.mark.parametrize("command", ["compare", "reproduce", "sweep"])
def test_directory_commands_refuse_a_file_or_read_only_out(command, scenario, tmp_path,
                                                           monkeypatch, capsys):
    _no_run(monkeypatch)
    first = {"compare": [str(scenario)], "reproduce": ["fig2"],
             "sweep": ["amplitude_precompression"]}[command]
    for out in (scenario, _unwritable(tmp_path) / "out"):
        assert main([command, *first, "--out", str(out)]) == 2, out
        err = capsys.readouterr().err
        assert "--out" in err and str(out) in err


def test_failed_final_write_prints_the_summary_and_keeps_the_checkpoint(
        scenario, tmp_path, monkeypatch, capsys):
    out = tmp_path / "r.h5"
    real_save = discrete.save

    def full_disk(path, *args, **kwargs):
        if Path(path) == out:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_save(path, *args, **kwargs)

    monkeypatch.setattr(discrete, "save", full_disk)
    code = main(["run", str(scenario), "--out", str(out), "--checkpoint-interval", "0"])
    std = capsys.readouterr()
    assert code == 2
    assert "stopped_by" in std.out and "energy_drift" in std.out  # the summary
    assert "disk full" in std.err and str(out) in std.err
    assert "checkpoint" in std.err and Path(str(out) + ".ckpt").exists()
    assert not out.exists()
    monkeypatch.setattr(discrete, "save", real_save)  # space freed: the rerun writes it
    assert main(["run", str(scenario), "--out", str(out)]) == 0
    assert out.exists() and not Path(str(out) + ".ckpt").exists()


# -- item 6: full disk ------------------------------------------------------------------
def test_enospc_inside_the_hdf5_writer_is_named_and_cleaned(tmp_path):
    target = tmp_path / "r.h5"
    target.write_bytes(b"old")
    with pytest.raises(OSError) as exc:
        with integrity.sealed_hdf5(target) as f:
            f.create_dataset("x", data=np.arange(1000.0))
            raise OSError(errno.ENOSPC, "No space left on device")
    assert exc.value.errno == errno.ENOSPC
    assert "disk full" in str(exc.value) and str(target) in str(exc.value)
    assert target.read_bytes() == b"old"  # the old file survives
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.h5"]  # no temporary left


def test_cli_full_disk_exits_2_with_disk_full(scenario, tmp_path, monkeypatch, capsys):
    def full_disk(path, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(discrete, "save", full_disk)
    assert main(["run", str(scenario), "--out", str(tmp_path / "r.h5")]) == 2
    assert "disk full" in capsys.readouterr().err


def _fsize_limit(limit: int):
    import resource

    def apply():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # EFBIG instead of a kill
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return apply


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_FSIZE fault injection: Linux")
def test_real_write_failure_midway_exits_cleanly(scenario, tmp_path):
    """The kernel refuses the HDF5 write half-way: exit 2 naming the file, no segfault
    (main: exit -11 / 139), no "Exception ignored" flood, no temporary left."""
    out = tmp_path / "r.h5"
    proc = subprocess.run([sys.executable, "-m", "hertzchain", "run", str(scenario),
                           "--out", str(out)], preexec_fn=_fsize_limit(120_000),
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert str(out) in proc.stderr and "Exception ignored" not in proc.stderr
    assert "stopped_by" in proc.stdout  # the summary survives the failed write
    assert not out.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


def test_hdf5_failure_raised_as_runtime_error_is_a_named_oserror(tmp_path):
    """h5py reports a failed write in a destructor as ``RuntimeError: Can't decrement id
    ref count (file write failed: ... errno = 28 ...)`` (the sweep's table on a full
    disk): it becomes "disk full ... PATH"."""
    target = tmp_path / "results.h5"
    text = ("Can't decrement id ref count (file write failed: time = now, filename = "
            "'x.tmp', file descriptor = 3, errno = 28, error message = 'No space left on "
            "device', buf = 0x0, total write size = 6400)")
    with pytest.raises(OSError) as exc:
        with integrity.sealed_hdf5(target) as f:
            f.create_dataset("x", data=np.arange(10.0))
            raise RuntimeError(text)
    assert exc.value.errno == errno.ENOSPC and "disk full" in str(exc.value)
    assert str(target) in str(exc.value) and list(tmp_path.iterdir()) == []


SWEEP = """\
[base.chain]
[[base.chain.sections]]
n = 30
[[base.chain.sections]]
n = 30
[base.run]
t_end = 1e-4
[[sweep.axes]]
path = "chain.sections.1.alpha_rho"
linspace = [0.5, 2.0, 400]
"""


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_FSIZE fault injection: Linux")
def test_sweep_table_write_failure_exits_cleanly(tmp_path):
    """The sweep's results.h5 fails half-way: exit 2 naming it (main: a RuntimeError
    traceback and a segfault)."""
    spec = tmp_path / "sw.toml"
    spec.write_text(SWEEP)
    out = tmp_path / "sw"
    proc = subprocess.run([sys.executable, "-m", "hertzchain", "sweep", str(spec), "--out",
                           str(out), "--workers", "1", "--no-progress", "--point-function",
                           "hertzchain.sweep.synthetic:synthetic_point"],
                          preexec_fn=_fsize_limit(30_000), capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert str(out / "results.h5") in proc.stderr
    assert not [p for p in out.iterdir() if p.name.endswith(".tmp")]


API_TABLE = """\
import gc, sys
from hertzchain.sweep import parse_sweep_spec
from hertzchain.sweep.store import write_table
spec = parse_sweep_spec({"base": {"chain": {"sections": [{"n": 30}, {"n": 30}]},
                                  "run": {"t_end": 1e-4}},
                         "sweep": {"axes": [{"path": "chain.sections.1.alpha_rho",
                                             "linspace": [0.5, 2.0, 400]}]}})
try:
    write_table(sys.argv[1], spec, spec.points(), {})
except OSError as exc:
    print("named:", exc, flush=True)
    del exc
gc.collect()
print("survived", flush=True)
"""


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_FSIZE fault injection: Linux")
def test_sweep_table_write_failure_through_the_api_does_not_crash(tmp_path):
    """A Python caller that catches the error goes on (main: a segfault when h5py freed
    the datasets of the failed file); the table is built in memory and written with one
    plain write."""
    target = tmp_path / "results.h5"
    proc = subprocess.run([sys.executable, "-c", API_TABLE, str(target)],
                          preexec_fn=_fsize_limit(30_000), capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert f"named: [Errno {errno.EFBIG}]" in proc.stdout and str(target) in proc.stdout
    assert "survived" in proc.stdout and "Exception ignored" not in proc.stderr
    assert list(tmp_path.iterdir()) == []
