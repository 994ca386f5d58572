import numpy as np
import pytest

from hertzchain.cache import atomic_path, cache_path, canonical_json, param_hash


def test_param_hash_is_canonical():
    a = {"alpha": 0.2, "n": 400, "nested": {"x": 1, "y": [1, 2]}}
    b = {"nested": {"y": [1, 2], "x": 1}, "n": 400, "alpha": 0.2}
    assert param_hash(a) == param_hash(b)
    assert param_hash(a) != param_hash({**a, "alpha": 0.2000001})
    assert canonical_json({"x": np.float64(0.5), "y": np.arange(2)}) == '{"x":0.5,"y":[0,1]}'


def test_cache_path(tmp_path):
    p = cache_path(tmp_path, "table2-M", {"a": 1})
    assert p.parent == tmp_path and p.name.startswith("table2-M-") and p.suffix == ".h5"


def test_atomic_path_success_and_failure(tmp_path):
    target = tmp_path / "out" / "r.txt"
    with atomic_path(target) as tmp:
        tmp.write_text("complete")
        assert not target.exists()
    assert target.read_text() == "complete"
    with pytest.raises(RuntimeError), atomic_path(target) as tmp:
        tmp.write_text("half")
        raise RuntimeError("crash")
    assert target.read_text() == "complete"
    assert sorted(p.name for p in target.parent.iterdir()) == ["r.txt"]


def test_atomic_path_file_mode_follows_umask(tmp_path):
    import os
    import stat

    old = os.umask(0o022)
    try:
        with atomic_path(tmp_path / "m.txt") as tmp:
            tmp.write_text("x")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "m.txt").stat().st_mode) == 0o644
