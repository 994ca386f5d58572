"""Compiled numba kernels are cached in a user cache directory, never inside a package.

Each case runs in a fresh interpreter (numba chooses a function's cache directory when
its decorator runs, once per process).  The install-order check itself (pip install . and
pip install -e . in both orders, twice) is a CI step: .ci/run with .ci/check_install.py.
"""

import os
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import pytest

import discrete


def _run(code: str, env_update: dict, cwd=None) -> str:
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR",
                                                            "XDG_CACHE_HOME")}
    env.update(env_update)
    out = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], env=env, cwd=cwd,
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


_PATHS = """
    import os, discrete.kernels as K, continuum._kernels as C
    print(os.environ["NUMBA_CACHE_DIR"])
    print(K.make_kernels().run_steps._cache.cache_path)
    print(C.face_strain._cache.cache_path)
"""


def test_default_is_user_cache_dir_outside_the_packages(tmp_path):
    env, k_path, c_path = _run(_PATHS, {"XDG_CACHE_HOME": str(tmp_path)}).splitlines()
    root = tmp_path / "hertzchain" / "numba"
    assert Path(env) == root
    packages = Path(discrete.__file__).parent.parent  # the directory holding our packages
    for path in (k_path, c_path):
        assert Path(path).parent == root
        assert not Path(path).is_relative_to(packages / "discrete")
        assert not Path(path).is_relative_to(packages / "continuum")
    assert Path(k_path).name.startswith("discrete_")
    assert Path(c_path).name.startswith("continuum_")


def test_user_numba_cache_dir_is_respected(tmp_path):
    mine = tmp_path / "mine"
    env, k_path, _ = _run(_PATHS, {"NUMBA_CACHE_DIR": str(mine),
                                   "XDG_CACHE_HOME": str(tmp_path / "xdg")}).splitlines()
    assert Path(env) == mine and Path(k_path).parent == mine
    assert not (tmp_path / "xdg").exists()


def test_unwritable_cache_home_falls_back_to_temp(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")  # XDG_CACHE_HOME under a file cannot be created
    env, k_path, _ = _run(_PATHS, {"XDG_CACHE_HOME": str(blocker / "x")}).splitlines()
    assert Path(env).name.startswith("hertzchain-numba-")
    assert Path(env).parent == Path(tempfile.gettempdir())
    assert Path(k_path).parent == Path(env)
    assert not Path(k_path).is_relative_to(Path(discrete.__file__).parent)


def test_cache_is_warm_tracks_the_index(tmp_path):
    src = tmp_path / "mykernels.py"
    src.write_text("from theory import jitcache\njitcache.configure()\n"
                   "import numba\n\n@numba.njit(cache=True)\ndef twice(x):\n    return 2 * x\n")
    code = """
        import mykernels
        from theory.jitcache import cache_is_warm
        before = cache_is_warm(mykernels.twice)
        mykernels.twice(3.0)
        print(before, cache_is_warm(mykernels.twice))
    """
    env = {"NUMBA_CACHE_DIR": str(tmp_path / "cache"), "PYTHONPATH": str(tmp_path)}
    assert _run(code, env, cwd=tmp_path) == "False True"   # cold, then compiled
    assert _run(code, env, cwd=tmp_path) == "True True"    # index on disk
    later = time.time() + 10                                # source edited after the index
    os.utime(src, (later, later))
    assert _run(code, env, cwd=tmp_path) == "False True"


_KEYED = """\
from theory.jitcache import keyed_njit


def _make():
    def f(x):
        return x + 1.0

    return keyed_njit(f, "test-compile-lock")


f = _make()
"""

_LOCKED = """\
import numba

from theory import jitcache

jitcache.configure()


@jitcache.compile_locked
@numba.njit(cache=True)
def f(x):
    return x + 1.0
"""

_HOLDER = """
    import sys, time
    import mykeyed
    from theory import jitcache
    with jitcache.compile_lock(mykeyed.f.compile_lock_path) as held:
        print("locked" if held else "not locked", flush=True)
        time.sleep(float(sys.argv[1]))  # the other process starts and must wait
        mykeyed.f(1.0)  # compiled here (inside the lock: not locked again)
    st = mykeyed.f.stats
    print(sum(st.cache_misses.values()), sum(st.cache_hits.values()), flush=True)
"""

_WAITER = """
    import time
    import mykeyed
    t = time.perf_counter()
    mykeyed.f(1.0)
    st = mykeyed.f.stats
    print(sum(st.cache_misses.values()), sum(st.cache_hits.values()),
          time.perf_counter() - t)
"""


@pytest.mark.parametrize("source", [_KEYED, _LOCKED], ids=["keyed_njit", "compile_locked"])
def test_a_kernel_compiles_once_across_processes(tmp_path, source):
    """A second process waits for the first one's compilation and loads its result
    (a keyed closure, and a module-level kernel under :func:`compile_locked`)."""
    (tmp_path / "mykeyed.py").write_text(source)
    env = {k: v for k, v in os.environ.items() if k != "XDG_CACHE_HOME"}
    env.update(NUMBA_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=os.pathsep.join(
        [str(tmp_path), str(Path(discrete.__file__).parent.parent)]))
    hold = 3.0
    holder = subprocess.Popen([sys.executable, "-c", textwrap.dedent(_HOLDER), str(hold)],
                              env=env, cwd=tmp_path, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        waiter = subprocess.run([sys.executable, "-c", textwrap.dedent(_WAITER)], env=env,
                                cwd=tmp_path, capture_output=True, text=True, timeout=300)
        assert waiter.returncode == 0, waiter.stderr
        out, _ = holder.communicate(timeout=300)
    finally:
        holder.kill()
    assert holder.returncode == 0
    assert out.split() == ["1", "0"]  # the holder compiled
    misses, hits, waited = waiter.stdout.split()
    assert (misses, hits) == ("0", "1")  # the waiter loaded the holder's result
    assert float(waited) > 0.0


def test_compile_locked_leaves_an_uncached_kernel_alone():
    """Without a disk cache there is no cache entry to share: the dispatcher is unchanged."""
    import numba

    from theory.jitcache import compile_locked

    def g(x):
        return x - 1.0

    disp = numba.njit(g)
    compile_ = disp.compile
    assert compile_locked(disp) is disp
    assert disp.compile == compile_ and not hasattr(disp, "compile_lock_path")
    assert disp(3.0) == 2.0
