"""Shared machinery of ``hertzchain reproduce``: context, cached runs, figures.

Every simulation of a reproduction item is identified by a JSON-able parameter dict;
its HDF5 file lives at :func:`hertzchain.cache.cache_path` ``(out/runs, stem, params)``
and is written atomically, so a re-run reuses every finished file and ``--force``
recomputes.  :class:`Context` carries the output directory, the mode (``quick`` or
``full``) and counts what was computed and what was reused (the tests check it).
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import h5py
import numpy as np

import discrete
import theory

from ..cache import atomic_path, cache_path, canonical_json
from ..paper import DIAMETER, V0

__all__ = ["MODES", "Context", "run_cached", "run_scenario_cached", "read_summary",
           "new_figure", "save_figure", "log_ticks", "two_section", "incident_wave", "tqdm_iter",
           "DIAMETER", "V0", "MATERIAL", "json_float"]

MODES = ("quick", "full")
MATERIAL = theory.PAPER_MATERIAL
"""Left-section material of every paper scenario: the Hertz constant with ν = 0.30
reproduces the paper's numbers (PHYSICS.md §1; ``theory.PAPER_MATERIAL``)."""


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
        Recompute even when a finished HDF5 file exists.
    progress : bool
        Show progress bars and messages on stderr.
    """

    out: Path
    mode: str = "quick"
    force: bool = False
    progress: bool = True
    computed: list[Path] = field(default_factory=list)
    reused: list[Path] = field(default_factory=list)
    timings: dict[str, float] = field(default_factory=dict)
    notes: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.out = Path(self.out)
        if self.mode not in MODES:
            raise ValueError(f"mode must be one of {MODES} (got {self.mode!r})")

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


def _params_attr(params: dict) -> str:
    return canonical_json(params)


def run_cached(ctx: Context, stem: str, params: dict,
               make: Callable[[], discrete.Simulation]) -> tuple[discrete.Simulation, Path]:
    """The finished simulation for ``params``: loaded from its HDF5 file or computed.

    Parameters
    ----------
    ctx : Context
    stem : str
        File-name stem (e.g. ``"fig2"``).
    params : dict
        Everything the result depends on (JSON-able); the cache key.
    make : callable
        Builds and runs the simulation (called only on a cache miss or with ``force``).

    Returns
    -------
    sim : discrete.Simulation
        With its recorded data (``sim.record``).
    path : pathlib.Path
        The HDF5 file.
    """
    path = cache_path(ctx.runs, stem, params)
    if path.exists() and not ctx.force:
        try:
            sim = discrete.load(path)
        except (OSError, ValueError, KeyError):  # unreadable: recompute
            sim = None
        if sim is not None:
            ctx.reused.append(path)
            return sim, path
    start = time.perf_counter()
    sim = make()
    with atomic_path(path) as tmp:
        discrete.save(tmp, sim)
        with h5py.File(tmp, "a") as f:
            f.attrs["reproduce_params"] = _params_attr(params)
            f.attrs["wall_time"] = time.perf_counter() - start
    ctx.computed.append(path)
    return sim, path


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
        except (OSError, ValueError, KeyError):
            summary = None
        if summary is not None:
            ctx.reused.append(path)
            return summary, path
    if full:
        summary = run_scenario(sc, out=path, progress=ctx.progress)
    else:
        summary = run_scenario(sc, progress=ctx.progress)
        with atomic_path(path) as tmp, h5py.File(tmp, "w") as f:
            f.attrs["scenario"] = canonical_json(params)
            f.attrs["summary"] = canonical_json(summary)
            f.attrs["format"] = "hertzchain.reproduce.summary/1"
    ctx.computed.append(path)
    return summary, path


def read_summary(path: str | Path) -> dict:
    """The runner's summary stored in an HDF5 file."""
    with h5py.File(path, "r") as f:
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
