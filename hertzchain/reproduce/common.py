"""Shared machinery of ``hertzchain reproduce``: context, cached runs, figures.

Every simulation of a reproduction item is identified by a JSON-able parameter dict;
its HDF5 file lives at :func:`hertzchain.cache.cache_path` ``(out/runs, stem, params)``
and is written atomically, so a re-run reuses every finished file and ``--force``
recomputes.  :class:`Context` carries the output directory, the mode (``quick`` or
``full``) and counts what was computed and what was reused (the tests check it).

Checkpoints (issue 8): a simulation is integrated in segments
(:func:`hertzchain.checkpoint.run_segmented`, bit for bit one ``Simulation.run`` call)
and written every ``Context.checkpoint_interval`` seconds of wall time to its HDF5 file's
name + ``.ckpt`` (:func:`hertzchain.checkpoint.checkpoint_path`), keyed by the same
parameters as the file.  After a kill, rerunning the same command reuses the finished
files and resumes the interrupted simulation from its checkpoint; the results are those
of an uninterrupted run, bit for bit.  SIGINT/SIGTERM during an integration write a
checkpoint and raise :class:`hertzchain.checkpoint.Interrupted` (exit status 130/143).
``--force`` discards the checkpoints with the finished files.
"""

from __future__ import annotations

import json
import math
import sys
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import discrete
import theory
from theory import integrity

from .. import checkpoint as C
from ..cache import atomic_path, cache_path, canonical_json
from ..paper import DIAMETER, V0

__all__ = ["MODES", "Context", "run_cached", "run_scenario_cached", "read_summary",
           "new_figure", "save_figure", "log_ticks", "two_section", "incident_wave", "tqdm_iter",
           "DIAMETER", "V0", "MATERIAL", "json_float"]

MODES = ("quick", "full")
MATERIAL = theory.PAPER_MATERIAL
"""Left-section material of every paper scenario: the Hertz constant with ν = 0.30
reproduces the paper's numbers (docs/physics.md §1; ``theory.PAPER_MATERIAL``)."""


@dataclass
class Context:
    """Where and how a reproduction runs.

    Parameters
    ----------
    out : path
        Output directory: ``runs/`` (HDF5 per simulation), ``figures/`` (PNG),
        ``cache/`` (settled incident waves), ``report.md``, ``report.html``.
    mode : {"quick", "full"}
        Size of the runs (each item module has ``QUICK`` and ``FULL`` defaults).
    force : bool
        Recompute even when a finished HDF5 file exists (and discard checkpoints).
    progress : bool
        Show progress bars and messages on stderr.
    checkpoint_interval : float or None
        Wall time between checkpoints of a simulation, s (>= 0; 0: after every segment).
        None: one uninterrupted ``Simulation.run`` call per simulation, no checkpoints.
    """

    out: Path
    mode: str = "quick"
    force: bool = False
    progress: bool = True
    checkpoint_interval: float | None = C.DEFAULT_INTERVAL
    computed: list[Path] = field(default_factory=list)
    reused: list[Path] = field(default_factory=list)
    timings: dict[str, float] = field(default_factory=dict)
    notes: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.out = Path(self.out)
        if self.mode not in MODES:
            raise ValueError(f"mode must be one of {MODES} (got {self.mode!r})")
        ci = self.checkpoint_interval
        if ci is not None and not (isinstance(ci, int | float) and not isinstance(ci, bool)
                                   and math.isfinite(ci) and ci >= 0):
            raise ValueError(f"checkpoint_interval must be None or a finite number of "
                             f"seconds >= 0 (got {ci!r})")

    @property
    def runs(self) -> Path:
        """Directory of the HDF5 files."""
        return self.out / "runs"

    @property
    def figures(self) -> Path:
        """Directory of the PNG files."""
        return self.out / "figures"

    @property
    def cache(self) -> Path:
        """Directory of the cached settled incident waves (``.npz``)."""
        return self.out / "cache"

    def log(self, message: str) -> None:
        """Print a progress message on stderr (if ``progress``)."""
        if self.progress:
            print(message, file=sys.stderr, flush=True)

    def pick(self, quick: dict, full: dict) -> dict:
        """A copy of the ``quick`` or ``full`` defaults of an item module, by mode."""
        return dict(full if self.mode == "full" else quick)


def tqdm_iter(ctx: Context, iterable: Iterable, *, desc: str, total: int | None = None):
    """A progress bar over ``iterable`` on stderr (plain iteration without progress)."""
    if not ctx.progress:
        return iterable
    from tqdm.auto import tqdm

    return tqdm(iterable, desc=desc, total=total, leave=False, file=sys.stderr)


def _retell(exc: C.Interrupted, ctx: Context, note: str) -> C.Interrupted:
    """``exc`` told for ``hertzchain reproduce`` (how to go on; --force discards)."""
    how = ("rerun the same command without --force to resume (--force discards "
           "checkpoints and finished files)" if ctx.force else
           "rerun the same command to resume (finished simulations are reused)")
    return C.Interrupted(exc.signum, exc.checkpoint, exc.t, exc.steps, note=f"{note}: {how}")


def _checkpoint_error(exc: C.CheckpointError) -> C.CheckpointError:
    """The runner's advice (--restart) in the terms of ``hertzchain reproduce``."""
    return C.CheckpointError(str(exc).replace("--restart", "--force"))


def run_cached(ctx: Context, stem: str, params: dict, *,
               build: Callable[[], discrete.Simulation], until=None,
               t_end: float | None = None) -> tuple[discrete.Simulation, Path]:
    """The finished simulation for ``params``: loaded from its HDF5 file or computed.

    ``build`` builds the simulation, ready to run; it is then run as
    ``sim.run(t_end, until=until)`` would, in checkpointed segments (module docstring),
    resuming from the checkpoint of an interrupted earlier run.

    Parameters
    ----------
    ctx : Context
    stem : str
        File-name stem (e.g. ``"fig2"``).
    params : dict
        Everything the result depends on (JSON-able); the cache key and the checkpoint
        key (:func:`hertzchain.checkpoint.run_key`).
    build : callable
        Builds the simulation, not run (called only on a cache miss, or with ``force``,
        when there is no checkpoint).
    until : event, optional
        Stop event of the run (:class:`discrete.WaveAt`, :class:`discrete.AtTime`).
    t_end : float, optional
        End time of the run, s.

    Returns
    -------
    sim : discrete.Simulation
        With its recorded data (``sim.record``).
    path : pathlib.Path
        The HDF5 file.

    Raises
    ------
    hertzchain.checkpoint.Interrupted
        SIGINT/SIGTERM during the integration (after writing the checkpoint), or while
        the finished result was being written (after writing it).
    hertzchain.checkpoint.CheckpointError
        The checkpoint is damaged or was written by incompatible code (``--force``
        discards it).
    """
    if until is None and t_end is None:
        raise TypeError("give until (event) and/or t_end (s)")
    path = cache_path(ctx.runs, stem, params)
    ckpt = C.checkpoint_path(path)
    if path.exists() and not ctx.force:
        try:
            sim = discrete.load(path)  # verified (theory.integrity)
        except (OSError, ValueError, KeyError) as exc:  # damaged or stale: recompute
            ctx.log(f"{stem}: recomputing the cached run: {exc}")
            sim = None
        if sim is not None:
            ctx.reused.append(path)
            return sim, path
    start = time.perf_counter()
    elapsed = 0.0  # wall time of earlier (interrupted) sessions
    key = C.run_key(params)
    C.remove_stale_temporaries(path)
    if ctx.force and ckpt.exists():
        ckpt.unlink()
        ctx.log(f"{stem}: removed the checkpoint {ckpt} (--force)")
    try:
        got = C.read_checkpoint(ckpt, key)
    except C.CheckpointError as exc:
        raise _checkpoint_error(exc) from None
    if got is not None:
        sim, extra = got
        elapsed = float(extra.get("wall_time", 0.0))
        ctx.log(f"{stem}: resuming from {ckpt}: t = {sim.t:.6g} s, step {sim.steps}")
    else:
        sim = build()
    if ctx.checkpoint_interval is None:
        sim.run(t_end, until=until, progress=ctx.progress)
        _save_result(path, sim, params, elapsed + time.perf_counter() - start)
        ctx.computed.append(path)
        return sim, path

    def extra() -> dict:
        return {"wall_time": elapsed + time.perf_counter() - start, "stem": stem}

    # SIGINT/SIGTERM: at a segment end, checkpoint and Interrupted; once the integration
    # is done, the result is written first and the interruption reported after it
    with C.deferred_signals() as late_signal:
        try:
            C.run_segmented(sim, t_end=t_end, until=until, checkpoint=ckpt, key=key,
                            interval=float(ctx.checkpoint_interval), extra=extra,
                            progress=ctx.progress, signals=late_signal)
        except C.Interrupted as exc:
            raise _retell(exc, ctx, f"checkpoint written to {ckpt}") from None
        _save_result(path, sim, params, elapsed + time.perf_counter() - start)
        ckpt.unlink(missing_ok=True)
        C.remove_stale_temporaries(path)
    ctx.computed.append(path)
    if late_signal:
        raise _retell(C.Interrupted(late_signal[0], None, sim.t, sim.steps), ctx,
                      f"the simulation had finished: result written to {path}")
    return sim, path


def _save_result(path: Path, sim: discrete.Simulation, params: dict, wall: float) -> None:
    """Write a finished simulation (atomically) with its parameters and wall time."""
    discrete.save(path, sim, attrs={"reproduce_params": canonical_json(params),
                                    "wall_time": wall})


def run_scenario_cached(ctx: Context, stem: str, scenario: dict, *, full: bool = True
                        ) -> tuple[dict, Path]:
    """Run a scenario (dict, :mod:`hertzchain.scenario`) with the runner, cached.

    Returns the runner's summary (:func:`hertzchain.runner.run_scenario`) and the HDF5
    file: with ``full`` the whole run (which :func:`discrete.load` reads back, with the
    recorded energy grid — several MB), otherwise a small file with only the scenario
    and the summary as JSON attributes (for sweeps of many points, e.g. Fig. 7).
    """
    from ..runner import run_scenario
    from ..scenario import parse_scenario

    sc = parse_scenario(scenario)
    params = sc.to_dict()
    path = cache_path(ctx.runs, stem, params)
    if path.exists() and not ctx.force:
        try:
            summary = read_summary(path)
        except (OSError, ValueError, KeyError) as exc:  # damaged or stale: recompute
            ctx.log(f"{stem}: recomputing the cached run: {exc}")
            summary = None
        if summary is not None:
            ctx.reused.append(path)
            return summary, path
    try:
        if full:  # checkpointed to path + ".ckpt" (--force: started over)
            summary = run_scenario(sc, out=path, progress=ctx.progress,
                                   checkpoint_interval=ctx.checkpoint_interval,
                                   resume=not ctx.force,
                                   log=lambda m: ctx.log(f"{stem}: {m}".replace(
                                       "--restart", "--force")))
        else:  # no output file, no checkpoint: the finished points are cached
            summary = run_scenario(sc, progress=ctx.progress,
                                   checkpoint_interval=ctx.checkpoint_interval)
    except C.CheckpointError as exc:
        raise _checkpoint_error(exc) from None
    except C.Interrupted as exc:
        if exc.checkpoint is not None:
            note = f"checkpoint written to {exc.checkpoint}"
        elif full:
            note = f"the simulation had finished: result written to {path}"
        else:
            note = f"this point is not saved, the {stem} points before it are"
        raise _retell(exc, ctx, note) from None
    if not full:
        with integrity.sealed_hdf5(path) as f:
            f.attrs["scenario"] = canonical_json(params)
            f.attrs["summary"] = canonical_json(summary)
            f.attrs["format"] = "hertzchain.reproduce.summary/1"
    ctx.computed.append(path)
    return summary, path


def read_summary(path: str | Path) -> dict:
    """The runner's summary stored in an HDF5 file (verified: :mod:`theory.integrity`).

    Raises
    ------
    ValueError
        Naming the file, if it is missing, unsealed or changed; KeyError without a
        summary.
    """
    with integrity.open_hdf5(path, what="cached result") as f:
        return json.loads(f.attrs["summary"])


def two_section(n_left: int, n_right: int, alpha_rho: float = 1.0, alpha_kn: float = 1.0,
                delta0_over_d: float = 0.0) -> discrete.Chain:
    """The paper's two-section chain with :data:`MATERIAL` on the left (paper Fig. 1)."""
    return discrete.Chain.two_section(n_left, n_right, alpha_rho, alpha_kn, delta0_over_d,
                                      material=MATERIAL, diameter=DIAMETER)


def incident_wave(ctx: Context, chain: discrete.Chain, centre: int) -> discrete.Initial:
    """The paper's incident wave, placed with its peak at grain ``centre``.

    The settled v0 = 1 m/s impact wave, cut out and placed (paper Section 2, end;
    :func:`discrete.cut_wave`), cached in ``ctx.cache``.
    """
    return discrete.cut_wave(chain, centre, v0=V0, cache_dir=ctx.cache)


def new_figure(nrows: int = 1, ncols: int = 1, *, figsize=(6.4, 4.0), **kwargs):
    """A matplotlib Figure (no pyplot state) and its axes array (always 2-D)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False, **kwargs)
    return fig, axes


def save_figure(ctx: Context, fig, name: str, *, dpi: int = 110) -> Path:
    """Save ``fig`` as ``figures/<name>.png`` (atomically) and return the path."""
    path = ctx.figures / f"{name}.png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format="png")
    return path


def log_ticks(ax, axis: str, ticks) -> None:
    """Plain-number major ticks at ``ticks`` on a log ``axis`` ("x" or "y"), no minor labels."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter

    a = ax.xaxis if axis == "x" else ax.yaxis
    a.set_major_locator(FixedLocator(list(ticks)))
    a.set_major_formatter(FuncFormatter(lambda x, _: f"{x:g}"))
    a.set_minor_formatter(NullFormatter())


def json_float(x: Any) -> Any:
    """``x`` as a plain float (NaN → None) for JSON output."""
    if x is None:
        return None
    x = float(x)
    return x if np.isfinite(x) else None
