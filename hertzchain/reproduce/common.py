"""Shared machinery of ``hertzchain reproduce``: context, the run path, figures.

Every simulation of a reproduction item is a scenario (the item's TOML file in
``hertzchain/scenarios/paper/`` with the mode's sizes set, or a scenario dict of the
same schema, :mod:`hertzchain.scenario`) run by :func:`run_models` through
:func:`hertzchain.models.run` — the run path of ``hertzchain run``, ``compare`` and
``sweep``.  Its HDF5 file lives at :func:`hertzchain.cache.cache_path` ``(out/runs, stem,
key)``, the key being everything the run depends on
(:meth:`hertzchain.scenario.Scenario.discrete_dict`), and is written atomically, so a
re-run reuses every finished file and ``--force`` recomputes.  :class:`Context` carries
the output directory, the mode (``quick`` or ``full``) and counts what was computed and
what was reused (the tests check it).

Checkpoints: a simulation is integrated in segments
(:func:`hertzchain.checkpoint.run_segmented`, bit for bit one ``Simulation.run`` call)
and written every ``Context.checkpoint_interval`` seconds of wall time to its HDF5 file's
name + ``.ckpt`` (:func:`hertzchain.checkpoint.checkpoint_path`), keyed by the same
scenario as the file.  After a kill, rerunning the same command reuses the finished
files and resumes the interrupted simulation from its checkpoint; the results are those
of an uninterrupted run, bit for bit.  SIGINT/SIGTERM during an integration write a
checkpoint and raise :class:`hertzchain.checkpoint.Interrupted` (exit status 130/143).
``--force`` discards the checkpoints with the finished files.
"""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import theory
from theory import integrity

from .. import checkpoint as C
from ..cache import atomic_path, cache_path, canonical_json
from ..paper import DIAMETER, V0

__all__ = ["MODES", "Context", "run_models", "run_scenario_cached", "run_point_cached",
           "read_summary",
           "replace_by_reduced",
           "paper_scenario", "ContinuumProfile", "continuum_profile", "plot_continuum",
           "continuum_sentence", "DIFF_SHOWN", "new_figure", "save_figure", "log_ticks",
           "tqdm_iter", "DIAMETER", "V0", "MATERIAL", "json_float"]

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
    compile_seconds: float = 0.0
    """CPU seconds numba spent compiling kernels during the items (a cold cache: the first
    run after installing), summed over the worker processes."""

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


def paper_scenario(name: str, values: dict | None = None):
    """The paper scenario ``hertzchain/scenarios/paper/<name>.toml`` with keys set.

    ``values`` maps dotted paths to values (``{"chain.sections.1.alpha_rho": 5.0}``,
    :meth:`hertzchain.scenario.Scenario.with_values`); every value is validated as if it
    had been written in the file.  The item modules keep only their sizes per mode.
    """
    from importlib.resources import files

    from ..scenario import load_scenario

    sc = load_scenario(files("hertzchain") / "scenarios" / "paper" / f"{name}.toml")
    return sc.with_values(values) if values else sc


def _count(ctx: Context, run_) -> None:
    """Add the result files of a :class:`hertzchain.models.Run` to the computed/reused lists."""
    for m in run_.models:
        if m.path is None or not (m.completed or m.cached):
            continue
        (ctx.reused if m.cached else ctx.computed).append(Path(m.path))


def run_models(ctx: Context, stem: str, scenario, *, samples: bool | None = None,
               save: bool = True):
    """Run every model of a scenario through :func:`hertzchain.models.run`, cached.

    The one run path of ``hertzchain run``, ``compare`` and ``sweep``: the discrete run
    is ``ctx.runs/<stem>-<hash>.h5`` (keyed by what it depends on, checkpointed beside
    it every ``ctx.checkpoint_interval`` seconds and resumed bit for bit after a kill),
    the continuum (if ``[models] continuum`` asks for it) ``<stem>-continuum-<hash>.h5``;
    finished files are reused, ``ctx.force`` recomputes.  The files are counted in
    ``ctx.computed``/``ctx.reused``.

    Parameters
    ----------
    ctx : Context
    stem : str
        File-name stem (e.g. ``"fig2"``).
    scenario : Scenario or dict
        A scenario (a dict is validated by :func:`hertzchain.scenario.parse_scenario`).
    samples : bool, optional
        Passed to :func:`hertzchain.models.run`.
    save : bool
        Write the discrete run to its file (default).  False: for items that keep a
        reduction of it (:func:`replace_by_reduced`); the run is still checkpointed
        beside that file name and resumed after a kill, but the finished run is not
        written (its discrete ``path`` is None unless a finished file was reused).

    Returns
    -------
    hertzchain.models.Run

    Raises
    ------
    hertzchain.checkpoint.Interrupted
        SIGINT/SIGTERM during a simulation (after writing its checkpoint), or while the
        finished result was being written (after writing it).
    hertzchain.checkpoint.CheckpointError
        The checkpoint is damaged or was written by incompatible code (``--force``
        discards it).
    """
    from ..models import run
    from ..scenario import Scenario, parse_scenario

    sc = scenario if isinstance(scenario, Scenario) else parse_scenario(scenario)
    try:
        result = run(sc, cache=ctx.runs, stem=stem, force=ctx.force,
                     checkpoint_interval=ctx.checkpoint_interval, progress=ctx.progress,
                     log=lambda m: ctx.log(f"{stem}: {m}"),
                     wave_cache=ctx.cache, samples=samples, save_discrete=save)
    except C.Interrupted as exc:
        if exc.checkpoint is not None:
            note = f"checkpoint written to {exc.checkpoint}"
        elif save:
            note = f"the {stem} simulation had finished and was written"
        else:
            note = f"the {stem} simulation had finished but was not kept"
        raise _retell(exc, ctx, note) from None
    _count(ctx, result)
    return result


def run_scenario_cached(ctx: Context, stem: str, scenario, *, full: bool = True
                        ) -> tuple[dict, Path]:
    """The discrete summary of a scenario (dict or Scenario), run by :func:`run_models`.

    Returns the runner's summary (:func:`hertzchain.runner.run_simulation`) and the HDF5
    file: with ``full`` the whole run (:func:`run_models`: cached and checkpointed;
    :func:`discrete.load` reads it back, with the recorded energy grid — several MB),
    otherwise a small file with only the scenario and the summary as JSON attributes
    (:func:`run_point_cached`; for sweeps of many points, e.g. Fig. 7), the run itself in
    memory only.  (Both take the scenario as it is: a dict is validated there.)
    """
    if full:
        result = run_models(ctx, stem, scenario)
        return dict(result.discrete.summary), Path(result.discrete.path)
    return run_point_cached(ctx, stem, scenario,
                            lambda result: dict(result.discrete.summary), kept=SUMMARY_KEPT)


SUMMARY_KEPT = "runner-summary/1"
"""What :func:`run_scenario_cached` keeps of a point: the runner's summary (version 1)."""


def run_point_cached(ctx: Context, stem: str, scenario, reduce, *, kept: str,
                     samples: bool | None = None) -> tuple[dict, Path]:
    """What an item keeps of one scenario's models, cached in a small HDF5 file.

    For items of many points that print a few numbers per point (Fig. 7's labels, the
    validity map's errors): every model of the scenario is run in memory by
    :func:`hertzchain.models.run` (the one run path; no run files, no checkpoints: a
    point takes seconds) and ``reduce(run)`` — a JSON-able dict (floats, also NaN, round
    trip exactly) — is written to ``ctx.runs/<stem>-<hash>.h5``, keyed by the scenario
    (:meth:`hertzchain.scenario.Scenario.to_dict`) and by ``kept``, sealed
    (:mod:`theory.integrity`), with the scenario, ``kept`` and the dict as JSON
    attributes (format ``hertzchain.reproduce.summary/1``).  A finished file is reused
    only if its scenario and ``kept`` are this call's (:func:`read_summary`; ``ctx.force``
    recomputes; a damaged or stale one is recomputed) and counted in ``ctx.computed`` /
    ``ctx.reused``.

    Parameters
    ----------
    ctx : Context
    stem : str
        File-name stem (e.g. ``"fig7"``).
    scenario : Scenario or dict
        A scenario (a dict is validated by :func:`hertzchain.scenario.parse_scenario`).
    reduce : callable
        ``reduce(run: hertzchain.models.Run) -> dict``, what is kept.
    kept : str
        Names what ``reduce`` keeps and its version (e.g. ``"validity-row/1"``): change
        it whenever ``reduce`` changes, so that no file of the old reduction is reused
        (a cached row is never recomputed otherwise).
    samples : bool, optional
        Passed to :func:`hertzchain.models.run` (True: sample the discrete chain at the
        common times even without a continuum, for :func:`hertzchain.compare.analyse`).

    Returns
    -------
    (dict, pathlib.Path)
        ``reduce``'s dict (read back from the file when reused) and the file.

    Raises
    ------
    hertzchain.checkpoint.Interrupted
        SIGINT/SIGTERM during the point's simulation (the points before it are kept).
    """
    from ..models import run
    from ..scenario import Scenario, parse_scenario

    sc = scenario if isinstance(scenario, Scenario) else parse_scenario(scenario)
    params = sc.to_dict()
    path = cache_path(ctx.runs, stem, {"scenario": params, "kept": kept})
    if path.exists() and not ctx.force:
        try:
            got = read_summary(path, scenario=params, kept=kept)
        except (OSError, ValueError, KeyError) as exc:  # damaged or stale: recompute
            ctx.log(f"{stem}: recomputing the cached run: {exc}")
            got = None
        if got is not None:
            ctx.reused.append(path)
            return got, path
    try:  # no output file, no checkpoint: the finished points are cached
        got = reduce(run(sc, progress=ctx.progress, wave_cache=ctx.cache,
                         checkpoint_interval=ctx.checkpoint_interval, samples=samples))
    except C.Interrupted as exc:
        raise _retell(exc, ctx, f"this point is not saved, the {stem} points before it "
                      "are") from None
    with integrity.sealed_hdf5(path) as f:
        f.attrs["scenario"] = canonical_json(params)
        f.attrs["kept"] = kept
        f.attrs["summary"] = canonical_json(got)
        f.attrs["format"] = "hertzchain.reproduce.summary/1"
    ctx.computed.append(path)
    return got, path


def read_summary(path: str | Path, *, scenario: dict | None = None,
                 kept: str | None = None) -> dict:
    """The dict stored by :func:`run_point_cached` (verified: :mod:`theory.integrity`).

    ``scenario`` (:meth:`~hertzchain.scenario.Scenario.to_dict`) and ``kept``, if given,
    must be the file's.

    Raises
    ------
    ValueError
        Naming the file, if it is missing, unsealed or changed, or holds another
        scenario or another ``kept``; KeyError without a summary.
    """
    with integrity.open_hdf5(path, what="cached result") as f:
        if scenario is not None and f.attrs["scenario"] != canonical_json(scenario):
            raise ValueError(f"{path}: the cached result is of another scenario")
        if kept is not None and f.attrs.get("kept") != kept:
            raise ValueError(f"{path}: the cached result keeps {f.attrs.get('kept')!r}, "
                             f"not {kept!r}")
        return json.loads(f.attrs["summary"])


def replace_by_reduced(ctx: Context, full: Path | None, store: Path) -> None:
    """Count the reduced file ``store`` for a run, in place of the run's own file ``full``.

    For items that keep only what they print (Table 2's points, Fig. 6's passages), run
    with ``run_models(..., save=False)``: the run was not written (``full`` None) and
    ``store`` is counted as computed; or a finished file of the run was reused
    (``full``): ``store`` takes its entry in ``ctx.computed``/``ctx.reused`` (one entry
    per simulation) and that file (snapshots, energy grids) is removed.
    """
    if full is None:
        ctx.computed.append(store)
        return
    for done in (ctx.computed, ctx.reused):
        done[:] = [store if q == full else q for q in done]
    Path(full).unlink()


DIFF_SHOWN = 0.05
"""The continuum − discrete velocity difference is drawn where it exceeds this fraction of
the incident peak velocity (the pulse threshold of Figs. 3 and 4): "where it is large"."""


@dataclass
class ContinuumProfile:
    """The continuum's grain velocities beside the discrete chain's at the snapshot.

    ``v`` (m/s, one per grain) is the continuum (:mod:`continuum`) run from the same
    initial grains to the discrete run's end time (:func:`hertzchain.models.run`), or
    None if it did not complete (``note`` says why).  ``numbers``: the model, the L2
    difference over the discrete profile's norm, the L∞ difference over the incident
    peak velocity, and the continuum's largest velocity right of the interface over the
    discrete chain's.
    """

    label: str
    v: np.ndarray | None
    note: str = ""
    numbers: dict = field(default_factory=dict)


def continuum_profile(result, v_disc: np.ndarray, reference: float,
                      interface: int | None = None) -> ContinuumProfile | None:
    """The continuum's final profile of a :func:`run_models` result (None if not run).

    ``reference``: the incident peak velocity (m/s); ``interface``: first grain of the
    second section (for the transmitted peak ratio).
    """
    c = result.continuum
    if c is None:
        return None
    if not c.completed or not c.times.size:
        return ContinuumProfile(c.label, None, f"the continuum did not complete "
                                f"({c.stopped_by})", {"model": c.summary.get("model", ""),
                                                      "completed": False})
    v = np.asarray(c.final_v)
    diff = v - v_disc
    norm = float(np.linalg.norm(v_disc))
    nums = {"model": c.summary.get("model", ""), "completed": True,
            "l2": float(np.linalg.norm(diff)) / norm if norm else math.nan,
            "linf_over_incident": float(np.max(np.abs(diff))) / reference,
            "energy_drift": float(c.summary.get("energy_drift", math.nan))}
    top = float(np.max(v_disc[interface:])) if interface is not None else 0.0
    if top > 0:
        nums["transmitted_max_v_ratio"] = float(np.max(v[interface:])) / top
    note = ""
    if c.t_final > c.valid_until:
        note = ("a wave reached a chain end, where the continuum's end condition differs, "
                f"at t = {c.valid_until * 1e3:.4g} ms")
    return ContinuumProfile(c.label, v, note, nums)


def plot_continuum(ax, prof: ContinuumProfile | None, v_disc: np.ndarray, reference: float,
                   *, scale: float = 1.0, start: int = 0, stop: int | None = None) -> None:
    """Draw the continuum's profile (dashed) and, where it is large, its difference.

    The difference continuum − discrete is drawn (red) only where it exceeds
    :data:`DIFF_SHOWN` × ``reference`` (the incident peak velocity, m/s); ``scale``
    divides the velocities (v0 for v/v0 axes); ``start``/``stop`` select grains.
    """
    if prof is None or prof.v is None:
        return
    stop = v_disc.size if stop is None else stop
    g = np.arange(start, stop)
    ax.plot(g + 1, prof.v[g] / scale, "--", color="C1", lw=0.8, label=prof.label)
    diff = prof.v[g] - v_disc[g]
    big = np.abs(diff) > DIFF_SHOWN * reference
    if big.any():
        ax.plot(g + 1, np.where(big, diff, np.nan) / scale, color="C3", lw=0.8,
                label=f"continuum − discrete (where > {DIFF_SHOWN:g} × incident)")


def continuum_sentence(profiles: list[tuple[str, ContinuumProfile | None]]) -> str:
    """One paragraph: how far the continuum is from the discrete chain at each snapshot."""
    parts = []
    for what, prof in profiles:
        if prof is None:
            continue
        if prof.v is None:
            parts.append(f"{what}: {prof.note}")
            continue
        n = prof.numbers
        text = (f"{what}: L2 difference {n['l2']:.2g} of the discrete profile, largest "
                f"{n['linf_over_incident']:.2g} × the incident peak velocity")
        if "transmitted_max_v_ratio" in n:
            text += (f", largest transmitted velocity {n['transmitted_max_v_ratio']:.3f} × "
                     "the discrete chain's")
        parts.append(text + (f" ({prof.note})" if prof.note else ""))
    if not parts:
        return ""
    label = next(p.label for _, p in profiles if p is not None)
    return (f"The {label} from the same initial grains, at the same time (dashed; red: "
            f"the difference where it exceeds {DIFF_SHOWN:g} × the incident peak "
            "velocity) — " + "; ".join(parts) + ".")


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
