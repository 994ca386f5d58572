"""Every file the package writes detects any change on read.

Before: only datasets of 64 or more entries were checksummed (Fletcher-32), so a
changed attribute or small dataset loaded silently — a checkpoint whose ``dt`` changed
resumed into a different run, a changed digit of a cached summary was reported as the
result — and 10/300 random bit flips in result files, 4/200 in checkpoints and 76/300
in a sweep's results.h5 went unnoticed; ``hertzchain info`` passed 226 of 300 damaged
files.  Now every file is sealed (:mod:`theory.integrity`: the SHA-256 of every byte
after a 512-byte header; the digest of its own text for a JSON line) and every reader
verifies it.

For each kind of file the package writes and reads back — a run's result file, a
checkpoint, a reproduce summary cache, a sweep's ``results.h5`` and ``records.jsonl``,
a per-point file of a sweep, the settled-wave ``.npz`` cache and a continuum
``FileStorage`` output — one bit is flipped at a random position (``FLIPS`` trials
per kind in the default suite, ``SLOW_FLIPS`` with ``--runslow``), and the package's own
reader of that file must refuse it with a ``ValueError`` naming the file (the settled
wave cache: recompute it, with a warning naming the file).  Targeted edits through
h5py (a changed attribute, one element of a small dataset) are found the same way.
"""

from __future__ import annotations

import json
import shutil
import warnings

import h5py
import numpy as np
import pytest

import discrete
import theory
from hertzchain import checkpoint as C
from hertzchain.cli import main
from hertzchain.files import describe
from hertzchain.reproduce.common import Context, read_summary, run_scenario_cached
from hertzchain.runner import build_simulation, run_scenario
from hertzchain.scenario import parse_scenario
from hertzchain.sweep import RecordStore, parse_sweep_spec, read_results, write_table
from hertzchain.sweep.engine import run_point
from hertzchain.sweep.synthetic import synthetic_point
from theory import integrity

FLIPS = 25
SLOW_FLIPS = 300

SCENARIO = {"name": "seal", "chain": {"delta0_over_d": 1e-3, "sections": [
    {"n": 150}, {"n": 200, "alpha_rho": 0.5, "alpha_kn": 2.0}]},
    "initial": {"kind": "exact_wave", "center": 75, "velocity_max": 0.0822},
    "run": {"t_end": 1e-4}, "record": {"snapshot_times": [5e-5], "time_series_grains": [10]}}
SWEEP = {"name": "seal", "base": SCENARIO, "sweep": {"axes": [
    {"path": "chain.sections.1.alpha_rho", "name": "ar", "values": [0.5, 2.0]}]}}
MASS, K, D = 1.0e-3, 1.0e10, 5e-3  # settled wave: a light steel-like grain, δ0 = 0


def _settled(cache_dir):
    return discrete.initial.settled_wave(MASS, K, 0.0, diameter=D, cache_dir=cache_dir)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """One file of each kind, written by the package's own writers."""
    d = tmp_path_factory.mktemp("sealed")
    out = {}
    sc = parse_scenario(SCENARIO)
    out["result"] = d / "run.h5"
    run_scenario(sc, out=out["result"])
    _, _, sim = build_simulation(sc)
    sim.run(5e-5, progress=False)
    out["checkpoint"] = C.write_checkpoint(d / "run.h5.ckpt", sim, C.run_key(sc.to_dict()),
                                           {"wall_time": 1.0})
    ctx = Context(out=d / "repro", progress=False, checkpoint_interval=None)
    _, out["summary_cache"] = run_scenario_cached(ctx, "seal", SCENARIO, full=False)
    spec = parse_sweep_spec(SWEEP)
    points = spec.points()
    store = RecordStore(d / "sweep" / "records.jsonl")
    recs = [run_point(synthetic_point, p.scenario, p.id, p.values,
                      out=str(d / "sweep" / f"{p.id}.h5")) for p in points]
    store.append_many(recs)
    out["records"] = store.path
    out["sweep_point"] = d / "sweep" / f"{points[0].id}.h5"
    out["sweep_table"] = write_table(d / "sweep" / "results.h5", spec, points,
                                     {r["id"]: r for r in recs})
    _settled(d / "cache")
    (out["settled_cache"],) = (d / "cache").glob("settled_wave_*.npz")
    out["continuum"] = _continuum_file(d / "continuum.h5")
    return out


def _continuum_file(path):
    from continuum import BoussinesqPDE, Medium, run, solitary_wave

    pde = BoussinesqPDE(Medium.uniform(40, 1e-3 * D), 3)
    run(pde, solitary_wave(pde, 10.0, velocity_max=0.0822), 2e-5, storage=path,
        interval=1e-5)
    return path


# -- the package's reader of each kind: returns normally on an intact file --------------
def _read_sweep_records(path):
    RecordStore(path).load()


def _read_settled(path):
    """The cache reader recomputes a bad file with a warning naming it (not an error)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        w = _settled(path.parent)
    bad = [str(c.message) for c in caught if issubclass(c.category, RuntimeWarning)]
    if bad:
        assert str(path) in bad[0]
        np.testing.assert_array_equal(w.v, _settled(None).v)  # recomputed, not read
        integrity.verify(path)  # and replaced by a sound file
        raise ValueError(bad[0])


READERS = {
    "result": [discrete.load, describe],
    "checkpoint": [lambda p: C.read_checkpoint(p, C.run_key(
        parse_scenario(SCENARIO).to_dict()))],
    "summary_cache": [read_summary],
    "records": [_read_sweep_records],
    "sweep_point": [describe],
    "sweep_table": [read_results],
    "settled_cache": [_read_settled],
    "continuum": [describe],
}


def test_intact_files_read(files):
    for kind, readers in READERS.items():
        for read in readers:
            read(files[kind])
    # the continuum output is still a py-pde file
    from pde import FileStorage

    storage = FileStorage(files["continuum"], write_mode="read_only")
    assert len(storage) == 3
    storage.close()


def _flip(src, dst, rng) -> tuple[int, int]:
    data = bytearray(src.read_bytes())
    pos, bit = int(rng.integers(len(data))), int(rng.integers(8))
    data[pos] ^= 1 << bit
    dst.write_bytes(bytes(data))
    return pos, bit


def _campaign(files, tmp_path, kind, n):
    rng = np.random.default_rng(abs(hash(kind)) % 2**32)
    src = files[kind]
    missed = []
    for trial in range(n):
        dst = tmp_path / f"t{trial}" / src.name
        dst.parent.mkdir()
        pos, bit = _flip(src, dst, rng)
        for read in READERS[kind]:
            try:
                read(dst)
            except ValueError as exc:  # IntegrityError, CheckpointError included
                assert str(dst) in str(exc), exc
            else:
                missed.append((read, pos, bit))
        shutil.rmtree(dst.parent)
    assert not missed, f"{len(missed)} of {n} flips in a {kind} file were not detected: " \
                       f"{missed[:5]}"


@pytest.mark.parametrize("kind", list(READERS))
def test_random_bit_flips_are_detected(files, tmp_path, kind):
    _campaign(files, tmp_path, kind, FLIPS)


@pytest.mark.slow
@pytest.mark.parametrize("kind", list(READERS))
def test_random_bit_flips_campaign(files, tmp_path, kind):
    _campaign(files, tmp_path, kind, SLOW_FLIPS)


def test_every_byte_of_a_checkpoint_is_covered(files, tmp_path):
    # exhaustive over the header and the first 4 kB: a flip anywhere is found
    src = files["checkpoint"]
    data = src.read_bytes()
    dst = tmp_path / "ck.h5"
    for pos in range(0, 4096):
        bad = bytearray(data)
        bad[pos] ^= 0x10
        dst.write_bytes(bytes(bad))
        with pytest.raises(integrity.IntegrityError):
            integrity.verify(dst)


# -- targeted edits through h5py: the cases of the issue -----------------------------------
def _next_after(ds) -> None:
    v = ds[()]
    i = int(np.argmax(np.abs(v)))
    v[i] = np.nextafter(v[i], np.inf)
    ds[...] = v


def _edit(src, dst, edit) -> None:
    shutil.copy(src, dst)
    with h5py.File(dst, "r+") as f:
        edit(f)


@pytest.mark.parametrize(("kind", "edit"), [
    ("checkpoint", lambda f: f.attrs.__setitem__("dt", f.attrs["dt"] * (1 + 2**-52))),
    ("checkpoint", lambda f: f.attrs.__setitem__("steps", f.attrs["steps"] + 1)),
    ("checkpoint", lambda f: _next_after(f["state/v"])),  # one ulp of one velocity
    ("result", lambda f: f.attrs.__setitem__("summary", f.attrs["summary"].replace(
        '"Ek_tr":0.', '"Ek_tr":1.'))),
    ("result", lambda f: f["chain/mass"].__setitem__(3, f["chain/mass"][3] * 2)),
    ("summary_cache", lambda f: f.attrs.__setitem__("summary", f.attrs["summary"].replace(
        '"dt":', '"dt":1'))),
    ("sweep_table", lambda f: f["table/status"].__setitem__(0, "ok")),
    ("sweep_table", lambda f: f.attrs.__setitem__("n_ok", 5)),
])
def test_changed_attribute_or_value_is_refused(files, tmp_path, kind, edit):
    dst = tmp_path / files[kind].name
    _edit(files[kind], dst, edit)
    for read in READERS[kind]:
        with pytest.raises(ValueError, match="does not match its SHA-256 seal|"
                                             "bytes of content where the seal says"):
            read(dst)


def test_changed_checkpoint_is_not_resumed(files, tmp_path, capsys):
    """The issue's case: a checkpoint with another dt resumed into a different run."""
    out = tmp_path / "run.h5"
    shutil.copy(files["checkpoint"], C.checkpoint_path(out))
    with h5py.File(C.checkpoint_path(out), "r+") as f:
        f.attrs["dt"] = f.attrs["dt"] * 1.01
    toml = tmp_path / "s.toml"
    toml.write_text(_toml(SCENARIO))
    assert main(["run", str(toml), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"{C.checkpoint_path(out)}: damaged checkpoint" in err and "--force" in err
    assert not out.exists()


def _toml(d: dict) -> str:
    lines = [f'name = "{d["name"]}"', "[chain]", f"delta0_over_d = {d['chain']['delta0_over_d']}"]
    for sec in d["chain"]["sections"]:
        lines += ["[[chain.sections]]"] + [f"{k} = {json.dumps(v)}" for k, v in sec.items()]
    for table in ("initial", "run", "record"):
        lines += [f"[{table}]"] + [f"{k} = {json.dumps(v)}" for k, v in d[table].items()]
    return "\n".join(lines) + "\n"


def test_changed_cached_summary_is_recomputed_with_a_message(files, tmp_path, capsys):
    """The issue's case: a changed digit of a cached summary was reported as the result."""
    ctx = Context(out=tmp_path / "repro", progress=True, checkpoint_interval=None)
    summary, path = run_scenario_cached(ctx, "seal", SCENARIO, full=False)
    good = dict(summary)
    with h5py.File(path, "r+") as f:
        text = f.attrs["summary"]
        f.attrs["summary"] = text.replace('"n_grains":350', '"n_grains":351')
    # (h5py may rewrite the attribute in place, caught by the seal's digest, or elsewhere
    # in a grown file, caught first by the seal's content size: either way refused)
    with pytest.raises(ValueError, match="does not match its SHA-256 seal|bytes of content "
                       "where the seal says"):
        read_summary(path)  # the reader refuses it ...
    again, _ = run_scenario_cached(ctx, "seal", SCENARIO, full=False)  # ... and recomputes
    assert again["n_grains"] == 350 and (again["steps"], again["dt"]) == (good["steps"], good["dt"])
    assert f"recomputing the cached run: {path}: damaged cached result" in \
        capsys.readouterr().err
    assert path in ctx.computed


def test_info_verifies_like_load(files, tmp_path, capsys):
    bad = tmp_path / "run.h5"
    _edit(files["result"], bad, lambda f: f.attrs.__setitem__("t", 0.0))
    assert main(["info", str(bad)]) == 2
    assert f"hertzchain: error: {bad}: damaged result file" in capsys.readouterr().err
    assert main(["info", str(files["result"])]) == 0


def test_sealed_json_lines():
    line = integrity.dumps_sealed_json({"id": "a", "x": 1.5, "nan": float("nan")})
    assert json.loads(line)["sha256"]  # still JSON
    rec = integrity.loads_sealed_json(line, where="l")
    assert rec["x"] == 1.5 and np.isnan(rec["nan"])
    for i in range(len(line)):
        for bit in range(8):
            b = bytearray(line.encode())
            b[i] ^= 1 << bit
            try:
                text = b.decode()
            except UnicodeDecodeError:
                continue
            with pytest.raises(integrity.IntegrityError, match="^l: damaged"):
                integrity.loads_sealed_json(text, where="l")


def test_records_name_the_file_and_line(files, tmp_path):
    path = tmp_path / "records.jsonl"
    shutil.copy(files["records"], path)
    lines = path.read_bytes().split(b"\n")
    lines[1] = lines[1].replace(b'"status":"ok"', b'"status":"ko"')
    path.write_bytes(b"\n".join(lines))
    with pytest.raises(ValueError, match=rf"{path} line 2: damaged .* Delete that line"):
        RecordStore(path).load()


def test_torn_last_record_is_cut_and_rewritten(files, tmp_path):
    path = tmp_path / "records.jsonl"
    data = files["records"].read_bytes()
    path.write_bytes(data[:-40])  # a crash while the last line was being appended
    store = RecordStore(path)
    assert len(store.load()) == 1  # the torn record is skipped: its point reruns
    rec = json.loads(data.split(b"\n")[1])
    rec.pop("sha256")
    store.append(rec)
    assert path.read_bytes() == data  # the torn piece was cut off, not kept as a line
    assert len(store.load()) == 2


def test_theory_does_not_import_h5py_at_import():
    import subprocess
    import sys

    code = "import sys, theory, theory.integrity; print('h5py' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True).stdout.strip() == "False"
    assert theory.integrity is integrity


def test_cached_point_of_another_kind_or_scenario_is_not_reused(tmp_path):
    """A cached point keeps what its ``kept`` names: another ``kept`` (a changed
    reduction) gets a file of its own, and a file holding another scenario than the
    one asked for is refused by the reader, so a stale row is never printed."""
    from hertzchain.reproduce.common import run_point_cached

    ctx = Context(out=tmp_path / "repro", progress=False, checkpoint_interval=None)
    one, p1 = run_point_cached(ctx, "pt", SCENARIO, lambda r: {"steps": r.discrete.summary[
        "steps"]}, kept="steps/1")
    two, p2 = run_point_cached(ctx, "pt", SCENARIO, lambda r: {"n": r.discrete.summary[
        "n_grains"]}, kept="n/1")
    assert p1 != p2 and one != two and ctx.computed == [p1, p2]
    again, p3 = run_point_cached(ctx, "pt", SCENARIO, lambda r: {}, kept="steps/1")
    assert (again, p3) == (one, p1) and ctx.reused == [p1]
    other = parse_scenario({**SCENARIO, "run": {"t_end": 2e-4}}).to_dict()
    with pytest.raises(ValueError, match="of another scenario"):
        read_summary(p1, scenario=other)
    with pytest.raises(ValueError, match="keeps 'steps/1', not 'n/1'"):
        read_summary(p1, kept="n/1")
    assert read_summary(p1, scenario=parse_scenario(SCENARIO).to_dict(),
                        kept="steps/1") == one
