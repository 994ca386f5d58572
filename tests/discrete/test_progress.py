"""Progress bars: a total and an ETA in grains or simulated time; the compile notice."""

import discrete
import discrete.progress as P
from discrete import WaveAt
from discrete.initial import impact


def _sim(n=300):
    return impact(discrete.Chain.two_section(n, 0)).simulation()


def test_grains_to_the_wave_target():
    sim = _sim()
    bar = P.RunProgress(sim, until=WaveAt(250), min_seconds=0)
    lo, hi = sim.window
    assert bar._mode == "grains" and bar._total == 250 - hi
    sim.run(until=WaveAt(250), progress=False)
    bar.update()
    assert bar._bar.n == bar._total     # the moving region has reached the target
    bar.close()


def test_simulated_time_and_steps():
    sim = _sim()
    bar = P.RunProgress(sim, t_end=1e-3, min_seconds=0)
    assert bar._mode == "time" and abs(bar._total - 1.0) < 1e-12   # ms
    sim.run(t_end=5e-4, progress=False)
    bar.update()
    assert abs(bar._bar.n - sim.t * 1e3) < 1e-9
    bar.close()
    steps = P.RunProgress(sim, step_limit=sim.steps + 100, min_seconds=0)
    assert steps._mode == "steps" and steps._total == 100
    steps.close()


def test_no_bar_when_disabled_or_nothing_to_measure():
    sim = _sim()
    assert P.RunProgress(sim, until=WaveAt(250), enabled=False)._mode is None
    # an event inside the moving region: no known distance, no end time
    assert P.RunProgress(sim, until=WaveAt(0))._mode is None


def test_compile_notice_when_the_cache_is_cold(monkeypatch, capsys):
    monkeypatch.setattr(P, "cache_is_warm", lambda dispatcher: False)
    sim = _sim()
    bar = P.RunProgress(sim, until=WaveAt(250), min_seconds=0)
    assert P.COMPILE_NOTICE in capsys.readouterr().err
    assert bar._bar is None                  # no bar while compiling
    sim.run(max_steps=10, progress=False)
    bar.update()
    assert "compiled in" in capsys.readouterr().err and bar._bar is not None
    bar.close()
    monkeypatch.setattr(P, "cache_is_warm", lambda dispatcher: True)
    P.RunProgress(_sim(), until=WaveAt(250)).close()
    assert P.COMPILE_NOTICE not in capsys.readouterr().err


def test_run_with_progress_reaches_its_event(capsys):
    info = _sim().run(until=WaveAt(250), progress=True)
    assert info.stopped_by == "wave_at=250"
