"""``hertzchain reproduce``: the paper's Figs. 2–8 and Table 2, end to end.

One small module per item, in the manner of pyro2's ``problems/<name>.py``: each has its
``QUICK`` and ``FULL`` defaults, a ``run(ctx, ...)`` returning numbers and arrays,
plotting functions that draw on a given matplotlib ``ax``, ``figures(ctx, result)``
saving the PNGs, ``report(rep, result, figures)`` adding its section to the report and
``to_json(result)``.

* :mod:`.fig2` — impact pulse, v̄max/v0 (0.6816, 0.0822) and the k_n convention;
* :mod:`.fig34` — Figs. 3 and 4, mass/stiffness mismatch at δ0 = 0;
* :mod:`.fig5` — precompressed cases a–d;
* :mod:`.fig6` — transmitted-front speed vs Eq. 5;
* :mod:`.fig7` — phase diagram, classified points vs theory;
* :mod:`.fig8` — space–time energy maps of M, N, P, Q;
* :mod:`.table2` — Table 2 (discrete, linear theory, continuum);
* :mod:`.common` — context, cached runs, figures; :mod:`.report` — the report.

Examples
--------
>>> from hertzchain.reproduce import reproduce
>>> out = reproduce(["fig2", "table2"], mode="quick", out="repro")  # doctest: +SKIP
>>> out["items"]["fig2"]["vmax_over_v0"]                            # doctest: +SKIP
{'0': 0.68163, '0.001': 0.082183}
"""

from __future__ import annotations

import importlib
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["ITEMS", "ItemRun", "run_item", "reproduce", "check_items", "kernel_threads"]

ITEMS = ("fig2", "fig3", "fig4", "fig5", "fig6", "fig7", "fig8", "table2", "validity")
"""Items in report order."""

_MODULES = {"fig2": ("fig2", {}), "fig3": ("fig34", {"item": "fig3"}),
            "fig4": ("fig34", {"item": "fig4"}), "fig5": ("fig5", {}), "fig6": ("fig6", {}),
            "fig7": ("fig7", {}), "fig8": ("fig8", {}), "table2": ("table2", {}),
            "validity": ("validity", {})}


@dataclass
class ItemRun:
    """What one item produced."""

    name: str
    module: object
    result: object
    figures: list = field(default_factory=list)
    numbers: dict = field(default_factory=dict)
    seconds: float = 0.0


def check_items(items) -> list[str]:
    """The items in report order, validated (default: all); ValueError for unknown names."""
    items = list(items or ITEMS)
    bad = [i for i in items if i not in ITEMS]
    if bad:
        raise ValueError(f"unknown item(s) {', '.join(map(repr, bad))}; choose from "
                         f"{', '.join(ITEMS)}")
    return [i for i in ITEMS if i in items]


def run_item(ctx, name: str) -> ItemRun:
    """Run one item: simulate (or reuse), analyse, save its figures."""
    mod_name, kwargs = _MODULES[name]
    mod = importlib.import_module(f"{__name__}.{mod_name}")
    start = time.perf_counter()
    result = mod.run(ctx, **kwargs)
    figs = mod.figures(ctx, result) if hasattr(mod, "figures") else []
    run = ItemRun(name, mod, result, figs, mod.to_json(result), time.perf_counter() - start)
    ctx.timings[name] = run.seconds
    return run


QUICK_THREADS = 1
"""Kernel threads of ``--quick`` (:func:`reproduce`'s default there).

Results are bitwise the same for every thread count (``tests/discrete/test_parallel.py``);
what one thread saves is the first compile.  On two cores a run whose window reaches
:data:`discrete.simulation.PARALLEL_MIN_GRAINS` (10,000; in ``--quick`` the settling of
the incident wave, Figs. 2 and 5) uses the blocked, threaded kernel, a second compiled
variant; on one thread every ``--quick`` run uses the plain kernel only (blocking pays on
one thread from :data:`discrete.simulation.SERIAL_BLOCK_MIN_GRAINS` grains).  Measured
(issue 13): settling the δ0/d = 1e-3 wave with an empty kernel cache, 29 s CPU on one
thread against 78 s on two, the same wave bit for bit."""


@contextmanager
def kernel_threads(threads: int | None):
    """Set numba's thread count for the solvers' kernels inside the block (None: unchanged).

    Capped at ``numba.config.NUMBA_NUM_THREADS``; the previous count is restored.
    """
    if threads is None:
        yield
        return
    import numba

    if int(threads) != threads or threads < 1:
        raise ValueError(f"threads must be None or an integer >= 1 (got {threads!r})")
    before = numba.get_num_threads()
    numba.set_num_threads(min(int(threads), int(numba.config.NUMBA_NUM_THREADS)))
    try:
        yield
    finally:
        numba.set_num_threads(before)


def reproduce(items=None, *, mode: str = "quick", out: str | Path = "hertzchain-reproduce",
              force: bool = False, progress: bool = True, report: bool = True,
              checkpoint_interval: float | None = 300.0,
              threads: int | None = None) -> dict:
    """Reproduce the given items and write the report.

    Parameters
    ----------
    items : sequence of str, optional
        Among :data:`ITEMS` (default: all).
    mode : {"quick", "full"}
        Run sizes (see each module's ``QUICK`` and ``FULL``).
    out : path
        Output directory.
    force : bool
        Recompute every simulation even if its HDF5 file exists (checkpoints discarded).
    progress : bool
        Progress bars and messages on stderr.
    report : bool
        Write ``report.md`` and ``report.html``.
    checkpoint_interval : float or None
        Wall time between checkpoints of a simulation, s (>= 0); after a kill, calling
        again with the same arguments resumes from the last one, bit for bit
        (:mod:`.common`).  None: no checkpoints.
    threads : int, optional
        Kernel threads of the discrete runs (:func:`kernel_threads`; the results are
        the same, bit for bit, for every count).  Default: :data:`QUICK_THREADS` in
        ``"quick"`` mode, numba's own count in ``"full"`` (Fig. 5's 50,000 grains).

    Returns
    -------
    dict
        ``items`` (each item's JSON numbers), ``runs`` (:class:`ItemRun` list), ``report``
        (paths), ``computed``/``reused`` (HDF5 files), ``wall_time`` (s).

    Raises
    ------
    hertzchain.checkpoint.Interrupted
        SIGINT/SIGTERM during a simulation, after writing its checkpoint.
    """
    from .common import Context

    names = check_items(items)
    ctx = Context(Path(out), mode=mode, force=force, progress=progress,
                  checkpoint_interval=checkpoint_interval)
    if threads is None and mode == "quick":
        threads = QUICK_THREADS
    start = time.perf_counter()
    runs = []
    with kernel_threads(threads):
        for k, name in enumerate(names, 1):  # "item k of n" before each item's messages
            ctx.log(f"[{k}/{len(names)}] {name} ({time.perf_counter() - start:.0f} s "
                    "elapsed)")
            runs.append(run_item(ctx, name))
    wall = time.perf_counter() - start
    paths = ()
    if report:
        from .report import write_report

        paths = write_report(ctx, runs, wall)
    return {"items": {r.name: r.numbers for r in runs}, "runs": runs, "report": paths,
            "computed": list(ctx.computed), "reused": list(ctx.reused), "wall_time": wall,
            "context": ctx}
