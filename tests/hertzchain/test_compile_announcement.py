"""A cold kernel cache is announced before the kernels compile, with the expected time.

The mechanism (:func:`theory.jitcache.announce_compilation`, numba's ``"numba:compile"``
event) is checked in-process on small functions compiled without a cache, so that each
call really compiles; the commands are checked in a fresh interpreter with an empty
``NUMBA_CACHE_DIR`` (the only way to make our cached kernels compile again).
"""

import os
import subprocess
import sys
import time

import numba
import pytest

from theory import jitcache


def _fresh_function(module: str, name: str = "f"):
    """A new (never compiled) numba function whose ``__module__`` is ``module``."""
    namespace = {"__name__": module}
    exec(f"def {name}(x):\n    return 2.0 * x + 1.0\n", namespace)
    return numba.njit(cache=False)(namespace[name])


def test_notice_before_compiling_once_per_family_and_block():
    log = []
    cont = _fresh_function("continuum._announce_test")
    # the notice is logged when the compile starts: the function has no signature yet
    record = lambda m: log.append((m, len(cont.signatures)))  # noqa: E731
    with jitcache.announce_compilation(log=record):
        assert cont(1.0) == 3.0
        _fresh_function("continuum._announce_test", "g")(1.0)  # same family: no second
        _fresh_function("tests_elsewhere", "h")(1.0)           # not ours: nothing
        assert not jitcache.announce("continuum")              # announced already
        with jitcache.announce_compilation(log=record):        # nested: one listener
            _fresh_function("discrete._announce_test")(1.0)
    assert [m for m, _ in log] == [jitcache.compile_notice("continuum") + " ...",
                                   jitcache.compile_notice("discrete") + " ..."]
    assert log[0][1] == 0                                      # before the compilation
    seconds = jitcache.KERNEL_FAMILIES["continuum"][1]
    assert f"about {seconds:.0f} s" in log[0][0] and "continuum solver" in log[0][0]
    log.clear()
    _fresh_function("discrete._announce_test")(1.0)            # outside a block: silent
    with jitcache.announce_compilation(enabled=False, log=record):
        _fresh_function("discrete._announce_test")(1.0)
    assert log == []


def test_announce_outside_a_block_and_bad_family(capsys):
    assert jitcache.announce("discrete") is True
    assert jitcache.compile_notice("discrete") in capsys.readouterr().err
    with pytest.raises(ValueError, match="family must be one of 'discrete', 'continuum'"):
        jitcache.compile_notice("theory")


TINY = """name = "tiny"
[chain]
delta0_over_d = 1e-3
[[chain.sections]]
n = 200
[[chain.sections]]
n = 200
alpha_rho = 2.0
[initial]
kind = "exact_wave"
center = 100
velocity_max = 0.05
[run]
t_end = 1e-4
[models]
continuum = "eq4"
nodes_per_grain = 3
"""


def _stream(argv, cwd, cache) -> list[tuple[float, str]]:
    """Run ``python -m hertzchain.cli argv``; its output lines (stdout and stderr merged)
    with the time each arrived."""
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["NUMBA_CACHE_DIR"] = str(cache)
    proc = subprocess.Popen([sys.executable, "-u", "-m", "hertzchain.cli", *argv], cwd=cwd,
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True)
    lines = [(time.monotonic(), line.rstrip("\n")) for line in proc.stdout]
    assert proc.wait(timeout=900) == 0, "\n".join(s for _, s in lines)[-3000:]
    return lines


def test_cold_run_announces_both_compilations_before_them(tmp_path):
    (tmp_path / "tiny.toml").write_text(TINY)
    lines = _stream(["run", "tiny.toml"], tmp_path, tmp_path / "numba")
    text = [s for _, s in lines]
    where = {fam: [i for i, s in enumerate(text) if s.startswith(jitcache.compile_notice(fam))]
             for fam in ("discrete", "continuum")}
    assert len(where["discrete"]) == 1 and len(where["continuum"]) == 1, text
    d, c = where["discrete"][0], where["continuum"][0]
    summary = next(i for i, s in enumerate(text) if s.startswith("scenario tiny"))
    assert d < c < summary, text
    # announced before the work: the discrete kernels compile for several seconds after
    # the notice (>= 1 s: a fast machine still takes far longer), then the run goes on
    assert lines[d + 1][0] - lines[d][0] > 1.0, text
    # warm: nothing announced
    again = [s for _, s in _stream(["run", "tiny.toml"], tmp_path, tmp_path / "numba")]
    assert not any("compiling" in s for s in again), again


@pytest.mark.slow
def test_cold_reproduce_announces_before_compiling(tmp_path):
    lines = _stream(["reproduce", "fig3", "--workers", "1", "--out", "r"], tmp_path,
                    tmp_path / "numba")
    text = [s for _, s in lines]
    d = text.index(next(s for s in text if s.startswith(jitcache.compile_notice("discrete"))))
    c = text.index(next(s for s in text if s.startswith(jitcache.compile_notice("continuum"))))
    first_item = next(i for i, s in enumerate(text) if s.startswith("[1/1] fig3"))
    written = next(i for i, s in enumerate(text) if s.startswith("written:"))
    assert first_item < d < c < written, text
    assert lines[d + 1][0] - lines[d][0] > 1.0, text
