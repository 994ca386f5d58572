"""Fig. 6 keeps a reduced file per (α_ρ, α_kn) instead of the run's snapshots.

The run's file (every grain at each passage of the leading peak) is reduced once to
``fig6-passages-<hash>.h5``: the passage grains and times and ξ_max, in float64.  Checked
on a short chain: one small file per α is left, a second run reuses it and gives exactly
the same windows, the numbers are those computed from the run's own snapshots, and a
changed file is recomputed, not read.
"""

import numpy as np
import pytest

from hertzchain.reproduce import fig6
from hertzchain.reproduce.common import Context, run_models

SMALL = {"alphas": (0.5, 2.0), "length": 150, "every": 10, "windows": (10, 50, 130)}


def _speeds(ctx):
    return fig6.run(ctx, **SMALL)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = tmp_path_factory.mktemp("f6")
    ctx1 = Context(out, progress=False, checkpoint_interval=None)
    first = _speeds(ctx1)
    ctx2 = Context(out, progress=False, checkpoint_interval=None)
    again = _speeds(ctx2)
    return out, ctx1, first, ctx2, again


def test_one_small_file_per_alpha_replaces_the_run_file(runs):
    out, ctx1, _, ctx2, _ = runs
    files = sorted((out / "runs").iterdir())
    assert len(files) == 4  # α_ρ = 0.5, 2 (α_kn = 1); α_kn = 0.5, 2 (α_ρ = 1)
    assert all(f.name.startswith("fig6-passages-") for f in files)
    assert max(f.stat().st_size for f in files) < 20_000  # measured ~10 kB (run file ~0.3 MB)
    assert sorted(ctx1.computed) == files and ctx1.reused == []
    assert ctx2.computed == [] and sorted(ctx2.reused) == files


def test_reused_windows_are_identical(runs):
    _, _, first, _, again = runs
    for which in first:
        for a, b in zip(first[which], again[which], strict=True):
            assert a.windows == b.windows and len(a.windows) == 2
            np.testing.assert_array_equal(a.times, b.times)
            np.testing.assert_array_equal(a.xi, b.xi)
            np.testing.assert_array_equal(a.distance, b.distance)
            assert (a.c0_left, a.c0_right, a.delta0_right) == (b.c0_left, b.c0_right,
                                                               b.delta0_right)


def test_passages_are_those_of_the_run_snapshots(tmp_path):
    # ξ_max and the times from the run's own snapshots, as Fig. 6 computed them before
    s = fig6.QUICK | SMALL
    ctx = Context(tmp_path, progress=False, checkpoint_interval=None)
    sim = run_models(ctx, "fig6", fig6.scenario(2.0, 1.0, s)).simulation
    p = fig6._passages(sim)
    snaps = [sn for sn in sim.record.snapshots if sn.label.startswith("wave_at=")]
    assert len(snaps) == p["grains"].size >= 10
    d0, d = sim.chain.delta0, float(sim.chain.diameter[0])
    for g, t, x, sn in zip(p["grains"], p["times"], p["xi"], snaps, strict=True):
        assert sn.label == f"wave_at={g}" and sn.t == t
        h = fig6.HALF
        assert x == np.max(sn.overlaps[g - h:g + h + 1] - d0[g - h:g + h + 1]) / d
    stored = fig6._speeds(2.0, 1.0, s, p)
    ctx2 = Context(tmp_path / "b", progress=False, checkpoint_interval=None)
    assert fig6._run(ctx2, 2.0, 1.0, s).windows == stored.windows


def test_changed_file_is_recomputed(runs, tmp_path):
    out, _, first, _, _ = runs
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    victim = sorted((copy / "runs").iterdir())[0]
    data = bytearray(victim.read_bytes())
    data[-200] ^= 0xFF  # one byte inside the file: the seal no longer holds
    victim.write_bytes(bytes(data))
    messages = []
    ctx = Context(copy, progress=False, checkpoint_interval=None)
    ctx.log = messages.append
    again = _speeds(ctx)
    assert ctx.computed == [victim] and len(ctx.reused) == 3
    assert any("recomputing" in m for m in messages)
    for which in first:
        assert [r.windows for r in again[which]] == [r.windows for r in first[which]]
