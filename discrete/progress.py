"""Progress of a run towards its stop condition: a tqdm bar with a total and an ETA.

:class:`RunProgress` measures progress in what the run is waiting for, so that its
total is known in advance and its ETA means something:

* a :class:`~discrete.WaveAt` stop (the wave reaching a grain): **grains**, from the
  edge of the moving region (the active window, :attr:`Simulation.window`) at the start
  to the target grain;
* else an end time: **simulated time**, in ms;
* else a step limit: steps.

A run with none of these (an unbounded ``until`` on an event inside the moving region)
gets no bar.  On the first run after installing, the numba kernels are compiled; if the
compiled cache is cold (:func:`theory.jitcache.cache_is_warm`) the compilation is
announced before the run starts, with its expected duration
(:func:`theory.jitcache.announce`: once, if a ``hertzchain`` command or an enclosing
:func:`theory.jitcache.announce_compilation` block has not announced it already), and
the bar starts only after the first chunk, so that the compilation does not distort the
ETA.  Bars and notices go to stderr.
"""

from __future__ import annotations

import math
import sys
import time

from theory.jitcache import announce, cache_is_warm, compile_notice

from .recording import WaveAt, as_event

__all__ = ["RunProgress", "COMPILE_NOTICE"]

COMPILE_NOTICE = compile_notice("discrete")
"""Printed before a run whose compiled kernels are not in the cache yet."""


class RunProgress:
    """A progress bar for ``Simulation.run``-like loops (see the module docstring).

    Parameters
    ----------
    sim : discrete.Simulation
        The simulation being run (read: ``t``, ``steps``, ``window``).
    t_end : float, optional
        Absolute end time, s.
    until : WaveAt, AtTime, int or float, optional
        The stop event.
    step_limit : int, optional
        Absolute step number at which the run stops.
    enabled : bool
        False: do nothing (no bar, no notice).
    desc : str, optional
        Label in front of the bar.
    min_seconds : float
        Show the bar only if the run is expected to take longer (tqdm's ``delay``).
    """

    def __init__(self, sim, *, t_end: float | None = None, until=None,
                 step_limit: int | None = None, enabled: bool = True,
                 desc: str | None = None, min_seconds: float = 1.0) -> None:
        self.sim = sim
        self.enabled = enabled
        self.desc = desc
        self.min_seconds = float(min_seconds)
        self._bar = None
        self._mode = None
        self._waiting_compile = False
        if not enabled:
            return
        event = as_event(until) if until is not None else None
        lo, hi = sim.window
        if isinstance(event, WaveAt) and lo >= 0 and not lo <= event.grain <= hi:
            self._mode = "grains"
            self._grain = int(event.grain)
            self._side = 1 if event.grain > hi else -1
            self._start = hi if self._side > 0 else lo
            self._total = abs(self._grain - self._start)
        elif t_end is not None and math.isfinite(float(t_end)) and float(t_end) > sim.t:
            self._mode = "time"
            self._t0 = sim.t
            self._total = (float(t_end) - sim.t) * 1e3
        elif step_limit is not None and step_limit > sim.steps:
            self._mode = "steps"
            self._s0 = sim.steps
            self._total = int(step_limit) - sim.steps
        if self._mode is not None and not cache_is_warm(sim.kernel):
            announce("discrete")
            self._waiting_compile = True
            self._clock = time.perf_counter()
        elif self._mode is not None:
            self._clock = time.perf_counter()  # tqdm is imported once the run lasts

    # ------------------------------------------------------------------ internals
    def _done(self) -> float:
        sim = self.sim
        if self._mode == "grains":
            lo, hi = sim.window
            edge = (hi if self._side > 0 else lo) if lo >= 0 else self._start
            return float(min(max(self._side * (edge - self._start), 0), self._total))
        if self._mode == "time":
            return min((sim.t - self._t0) * 1e3, self._total)
        return float(min(sim.steps - self._s0, self._total))

    def _open(self) -> None:
        from tqdm.auto import tqdm

        if self._mode == "grains":
            fmt = ("{desc}{percentage:3.0f}%|{bar}| {n:.0f}/{total:.0f} grains to grain "
                   f"{self._grain} " + "[{elapsed}<{remaining}]")
        elif self._mode == "time":
            fmt = ("{desc}{percentage:3.0f}%|{bar}| {n:.3f}/{total:.3f} ms simulated "
                   "[{elapsed}<{remaining}]")
        else:
            fmt = ("{desc}{percentage:3.0f}%|{bar}| {n:.0f}/{total:.0f} steps "
                   "[{elapsed}<{remaining}]")
        self._bar = tqdm(total=self._total, initial=self._done(), desc=self.desc,
                         bar_format=fmt, leave=False, file=sys.stderr, dynamic_ncols=True)

    # ------------------------------------------------------------------ API
    def update(self) -> None:
        """Move the bar to the simulation's present state."""
        if self._mode is None:
            return
        if self._waiting_compile:
            self._waiting_compile = False
            print(f"compiled in {time.perf_counter() - self._clock:.0f} s", file=sys.stderr,
                  flush=True)
            self._open()
            return
        if self._bar is None:  # (opened min_seconds after the start: tqdm's delay)
            if time.perf_counter() - self._clock < self.min_seconds:
                return
            self._open()
        self._bar.update(self._done() - self._bar.n)

    def close(self) -> None:
        """Close the bar (idempotent)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> RunProgress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
