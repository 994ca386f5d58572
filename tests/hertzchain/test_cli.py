"""The one command-line grammar (docs/guide/cli.md) and messages a user can act on.

Each test names the fault it pins down; every one failed on the command line before the
grammar was unified (checked against the code of that time).  New API is imported inside
the tests, so that each fault fails on its own against older code.
"""

from __future__ import annotations

import errno
import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from hertzchain.cli import main

ONE = """\
name = "one"
[chain]
delta0_over_d = 1e-3
[[chain.sections]]
n = 60
[initial]
kind = "impact"
[run]
t_end = 1e-4
"""

TWO = """\
name = "two"
[chain]
delta0_over_d = 1e-3
[[chain.sections]]
n = 60
[[chain.sections]]
n = 60
alpha_rho = 0.5
alpha_kn = 2.0
[initial]
kind = "impact"
[run]
t_end = 1e-4
"""


def _write(tmp_path, text: str, name: str = "s.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _strict_json(text: str):
    """json.loads that refuses NaN/Infinity (not JSON, RFC 8259)."""
    def bad(token):
        raise ValueError(f"not JSON: {token}")
    return json.loads(text, parse_constant=bad)


# -- --out: a directory, or the one file a command writes (.h5 / .png) -------------------
def test_run_out_directory_writes_scenario_named_file(tmp_path, capsys):
    toml = _write(tmp_path, ONE)
    out = tmp_path / "results"
    assert main(["run", str(toml), "--out", str(out), "--no-progress"]) == 0
    assert (out / "one.h5").is_file()
    assert f"written: {out / 'one.h5'}" in capsys.readouterr().out


def test_run_out_h5_file_still_a_file(tmp_path):
    toml = _write(tmp_path, ONE)
    assert main(["run", str(toml), "--out", str(tmp_path / "r.h5")]) == 0
    assert (tmp_path / "r.h5").is_file()


def test_run_out_refuses_to_replace_the_scenario(tmp_path, capsys):
    """Item 9: ``run s.toml --out s.toml`` replaced the scenario with HDF5, exit 0."""
    toml = _write(tmp_path, ONE)
    assert main(["run", str(toml), "--out", str(toml)]) == 2
    err = capsys.readouterr().err
    assert "--out" in err and "scenario file itself" in err
    assert toml.read_text() == ONE
    other = _write(tmp_path, "notes\n", "notes.txt")  # any file that is not a result
    assert main(["run", str(toml), "--out", str(other)]) == 2
    assert "not an HDF5 result" in capsys.readouterr().err and other.read_text() == "notes\n"


def test_plot_out_directory(tmp_path, capsys):
    """``plot --out DIR`` named a hidden temporary; now it writes DIR/<file>.png."""
    toml = _write(tmp_path, ONE)
    h5 = tmp_path / "r.h5"
    assert main(["run", str(toml), "--out", str(h5)]) == 0
    capsys.readouterr()
    figs = tmp_path / "figs"
    figs.mkdir()
    assert main(["plot", str(h5), "--out", str(figs)]) == 0
    out = capsys.readouterr()
    assert (figs / "r.png").stat().st_size > 1000
    assert ".tmp" not in out.out + out.err


# -- one flag spelling per meaning -------------------------------------------------------
def test_force_everywhere_restart_deprecated(tmp_path, capsys):
    toml = _write(tmp_path, ONE)
    out = tmp_path / "r.h5"
    assert main(["run", str(toml), "--out", str(out), "--force"]) == 0
    assert main(["run", str(toml), "--out", str(out), "--restart"]) == 0
    assert "--restart is deprecated; use --force" in capsys.readouterr().err


def test_theory_delta0_over_d(capsys):
    assert main(["theory", "--alpha-rho", "2", "--alpha-kn", "1", "--delta0-over-d", "1e-3",
                 "--json"]) == 0
    new = _strict_json(capsys.readouterr().out)
    assert new["delta0_over_d_left"] == 1e-3 and new["c0_left_m_per_s"] > 0
    assert main(["theory", "--alpha-rho", "2", "--alpha-kn", "1", "--delta0", "1e-3",
                 "--json"]) == 0
    out = capsys.readouterr()
    assert _strict_json(out.out) == new and "deprecated" in out.err


@pytest.mark.parametrize("command", ["run", "compare", "reproduce", "sweep"])
def test_every_command_with_progress_has_no_progress(command):
    from hertzchain.cli import build_parser

    first = {"run": ["x.toml"], "compare": ["x.toml"], "reproduce": ["fig3"],
             "sweep": ["tiny"]}[command]
    args = build_parser().parse_args([command, *first, "--no-progress"])
    assert args.no_progress is True


def test_help_says_shipped_names_and_lists_every_shipped_sweep():
    from hertzchain.cli import build_parser
    from hertzchain.sweep.spec import shipped_sweeps

    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command").choices
    assert "shipped" in sub["run"].format_help()
    sweep_help = " ".join(sub["sweep"].format_help().split())
    for name in shipped_sweeps():  # model_validity was missing
        assert name in sweep_help, name


# -- info: readable text and --json ------------------------------------------------------
def test_info_readable_and_json(tmp_path, capsys):
    toml = _write(tmp_path, ONE)
    h5 = tmp_path / "r.h5"
    assert main(["run", str(toml), "--out", str(h5)]) == 0
    capsys.readouterr()
    assert main(["info", str(h5)]) == 0
    text = capsys.readouterr().out
    assert "{'" not in text and "'}" not in text  # no Python dict reprs
    assert "datasets:" in text and "state/v" in text
    assert main(["info", str(h5), "--json"]) == 0
    info = _strict_json(capsys.readouterr().out)
    assert info["datasets"]["state/v"]["shape"] == [60]
    assert info["attributes"]["format"].startswith("hertzchain.discrete/")


# -- strict JSON -------------------------------------------------------------------------
def test_run_json_is_strict_json(tmp_path, capsys):
    """``run --json`` printed NaN/Infinity (compare --json printed null)."""
    toml = _write(tmp_path, ONE)
    assert main(["run", str(toml), "--json"]) == 0
    summary = _strict_json(capsys.readouterr().out)
    assert summary["Ek_tr"] is None  # one section: no interface quantity


# -- one section: no interface fields full of NaN -----------------------------------------
def test_one_section_summary_says_no_interface(tmp_path, capsys):
    toml = _write(tmp_path, ONE)
    assert main(["run", str(toml)]) == 0
    out = capsys.readouterr().out
    assert "Ek_tr" not in out and "separation_fraction" not in out
    assert "interface" in out and "none" in out
    assert " nan" not in out
    toml2 = _write(tmp_path, TWO, "two.toml")  # control: two sections keep them
    assert main(["run", str(toml2)]) == 0
    assert "Ek_tr" in capsys.readouterr().out


# -- did you mean ------------------------------------------------------------------------
def test_misspelt_table_key_and_name_get_did_you_mean(tmp_path, capsys):
    toml = _write(tmp_path, ONE.replace("[initial]", "[inital]"))
    assert main(["run", str(toml)]) == 2
    err = capsys.readouterr().err
    assert "unknown table [inital]; did you mean [initial]?" in err and "[models]" in err
    toml = _write(tmp_path, ONE.replace('kind = "impact"', 'kind = "impakt"'))
    assert main(["run", str(toml)]) == 2
    assert "did you mean 'impact'?" in capsys.readouterr().err
    toml = _write(tmp_path, ONE.replace("[chain]", '[chain]\nmaterial = "stel"'))
    assert main(["run", str(toml)]) == 2
    assert "did you mean 'steel'" in capsys.readouterr().err


# -- exit codes, no tracebacks -----------------------------------------------------------
HUGE = """\
[chain]
[[chain.sections]]
n = {n}
[run]
t_end = 1e-4
"""


@pytest.mark.parametrize("n", [10**12, 10**17])
def test_huge_chain_named_before_allocating(n, tmp_path, capsys):
    """``n = 1e12`` was a MemoryError traceback (build_chain before check_size); 1e17 an
    "array is too big" without the key."""
    toml = _write(tmp_path, HUGE.format(n=n))
    assert main(["run", str(toml)]) == 2
    err = capsys.readouterr().err
    assert "[chain.sections] n" in err and "does not fit in memory" in err
    assert "Traceback" not in err and "too big" not in err


def test_user_errors_exit_2_without_traceback(tmp_path):
    toml = _write(tmp_path, ONE.replace("n = 60", "n = 0"))
    proc = subprocess.run([sys.executable, "-m", "hertzchain", "run", str(toml)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert "n = 0 must be >= 1" in proc.stderr


# -- full disk: one message ---------------------------------------------------------------
def test_compare_full_disk_one_message(tmp_path, monkeypatch, capsys):
    """``compare`` on a full disk: exit 2, one message naming the disk (main: the message
    buried under h5py tracebacks).  Fault injected in the writer (OSError ENOSPC)."""
    import discrete

    def full_disk(path, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(discrete, "save", full_disk)
    toml = _write(tmp_path, TWO)
    assert main(["compare", str(toml), "--out", str(tmp_path / "c"), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("hertzchain: error:") == 1 and "disk full" in err
    assert "Traceback" not in err


def test_destructor_reports_of_failed_writes_are_absorbed(capsys):
    """h5py's destructor reports of failed flushes (excepthook + unraisablehook) are
    counted and end in one message, exit 2."""
    import argparse

    from hertzchain.cli import run_command

    def noisy(args):
        err = OSError(errno.ENOSPC, "Driver write request failed (file write failed: "
                      "errno = 28, error message = 'No space left on device')")
        for _ in range(5):
            sys.excepthook(OSError, err, None)
            sys.unraisablehook(type("U", (), {"exc_value": err, "exc_type": OSError,
                                              "exc_traceback": None, "err_msg": None,
                                              "object": None})())
        return 0

    assert run_command(argparse.Namespace(func=noisy)) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "disk full: 10 HDF5 write(s) failed" in err


def _tmpfs(tmp_path) -> Path:
    """A 300 KiB tmpfs (root only), or skip."""
    mnt = tmp_path / "full"
    mnt.mkdir()
    if os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("mounting a tmpfs needs root")
    proc = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=300k", "tmpfs", str(mnt)],
                          capture_output=True)
    if proc.returncode:
        pytest.skip(f"cannot mount a tmpfs: {proc.stderr.decode()[:200]}")
    return mnt


C300 = TWO.replace("n = 60", "n = 300").replace("t_end = 1e-4", "t_end = 1e-3")


@pytest.mark.skipif(sys.platform != "linux", reason="tmpfs: Linux")
@pytest.mark.parametrize("extra", [[], ["--checkpoint-interval", "0"]])
def test_real_full_disk_run(extra, tmp_path):
    """A 300 | 300 chain onto a 300 KiB tmpfs: main printed 26 h5py tracebacks and
    segfaulted (exit 139); with --checkpoint-interval 0 the message was buried under
    tracebacks.  Now: exit 2, one line, nothing left behind."""
    mnt = _tmpfs(tmp_path)
    try:
        toml = _write(tmp_path, C300)
        proc = subprocess.run([sys.executable, "-m", "hertzchain", "run", str(toml),
                               "--out", str(mnt / "r.h5"), "--no-progress", *extra],
                              capture_output=True, text=True, timeout=600)
        assert proc.returncode == 2, proc.stderr[-2000:]
        assert "Traceback" not in proc.stderr and "Exception ignored" not in proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and "disk full" in lines[0] and str(mnt) in lines[0]
        assert not list(mnt.iterdir())
    finally:
        subprocess.run(["umount", str(mnt)], capture_output=True)


# -- messages that name the key and the cause --------------------------------------------
def test_roundoff_drift_is_not_called_dt_too_large():
    """Item 11: a precompressed chain at v0 = 1e-6 failed with "dt too large" though the
    drift is round-off of the static energy (it scales as 1/v0², a smaller dt makes it
    worse)."""
    from discrete import InstabilityError
    from hertzchain.runner import run_scenario
    from hertzchain.scenario import parse_scenario

    sc = parse_scenario({"chain": {"delta0_over_d": 1e-3, "sections": [{"n": 100}]},
                         "initial": {"v0": 1e-6}, "run": {"t_end": 2e-4}})
    with pytest.raises(InstabilityError) as err:
        run_scenario(sc)
    msg = str(err.value)
    assert "round-off" in msg and "dt too large" not in msg and "floor" in msg


def test_too_large_dt_still_diagnosed_as_dt():
    """Control: the same chain at v0 = 1 with dt = 0.6 × the linear bound drifts because
    of dt (drift far above the round-off floor): the message says so."""
    from discrete import InstabilityError
    from hertzchain.runner import _stable_and_auto_dt, build_simulation
    from hertzchain.scenario import parse_scenario

    sc = parse_scenario({"chain": {"delta0_over_d": 1e-3, "sections": [{"n": 100}]},
                         "initial": {"v0": 1.0}, "run": {"t_end": 2e-4}})
    _, init, _ = build_simulation(sc)
    stable, _ = _stable_and_auto_dt(init, sc.chain)
    _, _, sim = build_simulation(sc.with_values({"run.dt": 0.6 * stable}))
    with pytest.raises(InstabilityError, match="dt too large"):
        sim.run(t_end=2e-4)
    assert sim.roundoff_floor() < 1e-12 * sim.energy0  # ε·ΣF0δ0 ≪ the wave's energy


def test_roundoff_floor_is_eps_times_static_work():
    """roundoff_floor = ε Σ_j F(δ0_j) δ0_j, from theory's static force (independent)."""
    import theory
    from hertzchain.runner import build_simulation
    from hertzchain.scenario import parse_scenario

    sc = parse_scenario({"chain": {"delta0_over_d": 1e-3, "sections": [{"n": 50}]},
                         "run": {"t_end": 1e-5}})
    chain, _, sim = build_simulation(sc)
    d = 5e-3
    k = theory.hertz_constant(d, theory.PAPER_MATERIAL)
    d0 = 1e-3 * d
    expected = np.finfo(float).eps * (chain.n + 1) * k * d0**1.5 * d0
    assert sim.roundoff_floor() == pytest.approx(expected, rel=1e-12)


def test_gravity_roundoff_is_diagnosed(tmp_path, capsys):
    toml = _write(tmp_path, "[chain]\ngravity = 9.81\n[[chain.sections]]\nn = 100\n"
                  "[initial]\nv0 = 1e-9\n[run]\nt_end = 2e-3\n[models]\ntheory = false\n")
    assert main(["run", str(toml)]) == 2
    err = capsys.readouterr().err
    assert "round-off" in err and "dt too large" not in err


def test_free_end_single_grain_section_names_the_key(tmp_path, capsys):
    """``sections = [{n=10},{n=1}]`` with a free end: "k_n must be > 0 (got 0.0)"."""
    toml = _write(tmp_path, "[chain]\nright_wall = \"free\"\n[[chain.sections]]\nn = 10\n"
                  "[[chain.sections]]\nn = 1\n[run]\nt_end = 1e-4\n")
    assert main(["run", str(toml)]) == 2
    err = capsys.readouterr().err
    assert "[chain.sections[1]] n = 1" in err and "right_wall" in err


def test_dt_fraction_in_range_or_named(tmp_path, capsys):
    """``dt_fraction = 1.0`` (inside (0, 1]) failed citing ``check_dt=False``."""
    from hertzchain.scenario import ScenarioError, parse_scenario

    with pytest.raises(ScenarioError, match=r"\[run\] dt_fraction = 1.0 must be|"
                                            r"\[run\] dt_fraction = 1.0 is outside"):
        parse_scenario({"chain": {"sections": [{"n": 10}]},
                        "run": {"t_end": 1e-4, "dt_fraction": 1.0}})
    toml = _write(tmp_path, TWO.replace("t_end = 1e-4", "t_end = 1e-5\ndt_fraction = 0.3"))
    assert main(["run", str(toml)]) == 2
    err = capsys.readouterr().err
    assert "[run] dt_fraction = 0.3" in err and "check_dt" not in err
    assert "allowed range (0, 0.22" in err  # √2/(2π) for these identical contacts


def test_striker_counts_in_record_indices(tmp_path):
    """With a striker the run's grain 0 is the striker (as documented), so ``sensors =
    [100]`` on n = 100 is the chain's last grain; it was refused."""
    from hertzchain.runner import run_scenario
    from hertzchain.scenario import ScenarioError, parse_scenario

    base = {"chain": {"delta0_over_d": 1e-3, "sections": [{"n": 100}]},
            "initial": {"striker_mass": 2.0}, "run": {"t_end": 5e-5},
            "record": {"sensors": [100]}}
    result = run_scenario(parse_scenario(base), out=tmp_path / "s.h5")
    assert result["n_grains"] == 101
    with pytest.raises(ScenarioError, match=r"allowed range \[0, 100\] for 100 grains and "
                                            r"the striker"):
        parse_scenario({**base, "record": {"sensors": [101]}})


def test_integer_ranges_accept_what_they_document():
    """``half_width = 30`` and ``seed = 0`` were accepted outside their documented ranges:
    every integer key now accepts its documented bound exactly when the range includes it."""
    from hertzchain.scenario import SCHEMA, ScenarioError, read_key

    checked = 0
    for table, keys in SCHEMA.items():
        for key in keys:
            if key.kind not in ("integer", "integers") or key.low is None:
                continue
            value = int(key.low) if key.kind == "integer" else [int(key.low)]
            inside = key.range_text().startswith("[")
            try:
                read_key(table, key.name, value)
                accepted = True
            except ScenarioError:
                accepted = False
            assert accepted == inside, (table, key.name, key.range_text())
            checked += 1
    assert checked >= 10


def test_default_seed_differs_between_sections():
    """Two disordered sections with the default seed got identical disorder."""
    from hertzchain.runner import build_chain
    from hertzchain.scenario import parse_scenario

    sec = {"n": 40, "disorder_mass": 0.1}
    sc = parse_scenario({"chain": {"sections": [sec, dict(sec)]}, "run": {"t_end": 1e-4},
                         "models": {"theory": False}})
    m = build_chain(sc.chain).mass
    assert not np.allclose(m[:40], m[40:])
    assert [s.seed for s in sc.chain.sections] == [0, 1]
    # an explicit seed is kept (same disorder on purpose)
    sc = parse_scenario({"chain": {"sections": [{**sec, "seed": 3}, {**sec, "seed": 3}]},
                         "run": {"t_end": 1e-4}, "models": {"theory": False}})
    m = build_chain(sc.chain).mass
    assert np.array_equal(m[:40], m[40:])


def test_sweep_cli_lists_match_the_spec():
    from hertzchain.sweep.cli import shipped_sweep_names
    from hertzchain.sweep.spec import shipped_sweeps

    assert shipped_sweep_names() == sorted(shipped_sweeps())


def test_materials_command(capsys):
    assert main(["materials", "--json"]) == 0
    rows = _strict_json(capsys.readouterr().out)
    names = {r["name"] for r in rows}
    assert {"stainless_steel_316", "brass", "ptfe", "soda_lime_glass", "tungsten_carbide",
            "nylon_66", "aluminium_6061", "chrome_steel_52100", "paper", "table1"} <= names
    assert all(r["source"] for r in rows)
    assert main(["materials"]) == 0
    text = capsys.readouterr().out
    assert "kg/m³" in text and "GPa" in text and "Daraio" in text


def test_theory_with_materials(capsys):
    import theory

    assert main(["theory", "--left", "steel", "--right", "brass", "--json"]) == 0
    out = _strict_json(capsys.readouterr().out)
    a_rho, a_kn = theory.material_ratios(theory.get_material("steel"),
                                         theory.get_material("brass"))
    assert out["alpha_rho"] == a_rho and out["alpha_kn"] == a_kn
    assert main(["theory", "--alpha-rho", repr(a_rho), "--alpha-kn", repr(a_kn),
                 "--json"]) == 0
    by_ratio = _strict_json(capsys.readouterr().out)
    assert all(out[k] == v for k, v in by_ratio.items() if k not in ("alpha_rho",
                                                                      "alpha_kn"))
    assert main(["theory", "--right", "brss"]) == 2
    assert "--right" in capsys.readouterr().err
    assert math.isfinite(out["gamma_c0"])


def test_a_sweep_point_on_a_full_disk_is_one_failed_record(capsys):
    """A sweep's point whose HDF5 objects fail to flush on a full disk: h5py reports it
    from destructors (sys.unraisablehook), which in a Dask worker printed a traceback per
    object.  run_point counts them (hertzchain.faults.FailedWrites): one failed record
    naming the disk, nothing on stderr."""
    import errno

    from hertzchain.sweep.engine import run_point
    from hertzchain.sweep.store import SUMMARY_FIELDS

    class Dataset:  # stands in for an h5py object whose flush fails in __del__
        def __del__(self):
            raise OSError(errno.ENOSPC, "No space left on device")

    def point(scenario, out=None, progress=False):
        d = Dataset()
        del d  # the destructor's error goes to sys.unraisablehook
        return {**{key: 0.0 for key in SUMMARY_FIELDS}, "completed": True}

    rec = run_point(point, None, "p0", {})
    err = capsys.readouterr().err
    assert rec["status"] == "failed" and "disk full: 1 HDF5 write(s) failed" in rec["error"]
    assert "Traceback" not in err and "No space left" not in err
