"""Damaged or stale caches.

A killed cache write left its temporary forever; ``--force`` kept the cached settled
waves; a damaged cached run of ``run``/``compare`` was recomputed without a word.  A
truncated settled-wave ``.npz`` is recomputed with a warning naming it, and cache files
get the mode of a normally created file (both also checked here).
"""

from __future__ import annotations

import os
import stat
import subprocess
import sys
import warnings

import pytest

import discrete
from hertzchain import cache
from hertzchain.cli import main
from hertzchain.models import run
from hertzchain.scenario import parse_scenario
from theory.integrity import umask

WAVE = {"mass": 5e-4, "k": 1e10, "delta0": 0.0, "diameter": 5e-3, "v0": 1.0}


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_stale_temporaries_removed_live_kept(tmp_path):
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
    try:
        dead = tmp_path / f".settled_wave_ab.npz.{_dead_pid()}-x1y2.tmp"
        alive = tmp_path / f".settled_wave_cd.npz.{live.pid}-z3w4.tmp"
        old = tmp_path / ".settled_wave_ef.npz.q9r8s7.tmp"
        keep = tmp_path / "settled_wave_ab.npz"
        for p in (dead, alive, old, keep):
            p.write_bytes(b"x")
        assert set(cache.remove_stale_temporaries(tmp_path)) == {dead, old}
        assert alive.exists() and keep.exists()
    finally:
        live.kill()
        live.wait()


def test_truncated_settled_wave_is_recomputed_named_and_shared(tmp_path):
    w = discrete.settled_wave(**WAVE, cache_dir=tmp_path)
    (path,) = tmp_path.glob("settled_wave_*.npz")
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~umask()  # not 0600
    path.write_bytes(path.read_bytes()[:200])  # truncated
    with pytest.warns(RuntimeWarning, match=path.name):
        again = discrete.settled_wave(**WAVE, cache_dir=tmp_path)
    assert (again.u == w.u).all() and path.stat().st_size > 200


def test_force_clears_the_settled_waves(tmp_path, monkeypatch, capsys):
    import hertzchain.compare

    runs = tmp_path / "out" / "runs"
    runs.mkdir(parents=True)
    wave = runs / "settled_wave_0123456789abcdef.npz"
    wave.write_bytes(b"damaged")
    stale = runs / f".{wave.name}.{_dead_pid()}-abcd.tmp"
    stale.write_bytes(b"partial")

    def stop(*args, **kwargs):
        raise ValueError("stopped after the caches were cleaned")

    monkeypatch.setattr(hertzchain.compare, "compare", stop)
    scenario = tmp_path / "s.toml"
    scenario.write_text('[chain]\n[[chain.sections]]\nn = 40\n[run]\nt_end = 1e-4\n')
    assert main(["compare", str(scenario), "--out", str(tmp_path / "out")]) == 2
    assert wave.exists() and not stale.exists()  # a killed write's temporary: gone
    assert main(["compare", str(scenario), "--out", str(tmp_path / "out"), "--force"]) == 2
    assert not wave.exists()
    err = capsys.readouterr().err
    assert "left by a killed writer" in err and "(--force)" in err


def test_damaged_cached_run_is_recomputed_and_says_so(tmp_path):
    sc = parse_scenario({"chain": {"sections": [{"n": 40}]}, "run": {"t_end": 1e-4},
                         "models": {"theory": False}})
    first = run(sc, cache=tmp_path)
    (path,) = [p for p in tmp_path.glob("*.h5")]
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~umask()
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))
    said: list[str] = []
    again = run(sc, cache=tmp_path, log=said.append)
    assert any("recomputing the cached run" in m and str(path) in m for m in said), said
    assert not again.discrete.cached and again.discrete.summary["steps"] == \
        first.discrete.summary["steps"]
    with warnings.catch_warnings(record=True) as caught:  # without a log: a warning
        warnings.simplefilter("always")
        path.write_bytes(b"garbage")
        run(sc, cache=tmp_path)
    assert any("recomputing the cached run" in str(w.message) for w in caught)


def test_cut_wave_run_cleans_its_cache_directory(tmp_path):
    from hertzchain.runner import build_initial

    stale = tmp_path / f".settled_wave_x.npz.{_dead_pid()}-k.tmp"
    stale.write_bytes(b"partial")
    sc = parse_scenario({"chain": {"sections": [{"n": 200}]},
                         "initial": {"kind": "cut_wave", "center": 100},
                         "run": {"t_end": 1e-4}})
    build_initial(sc, discrete.Chain.two_section(200, 0), cache_dir=tmp_path)
    assert not stale.exists()
    assert [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")] == []
    assert os.listdir(tmp_path)  # the settled wave itself is cached
