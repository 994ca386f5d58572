"""Command-line front end: ``hertzchain sweep`` and ``hertzchain plot-sweep``.

:func:`add_sweep_parsers` registers both sub-commands on the ``hertzchain`` parser;
``python -m hertzchain.sweep`` runs them stand-alone.
"""

from __future__ import annotations

import argparse
import copy
import dataclasses
import sys
from collections.abc import Sequence
from pathlib import Path

from .._argtypes import positive_float, positive_int

__all__ = ["add_sweep_parsers", "cmd_sweep", "cmd_plot_sweep", "exit_status", "main",
           "EXIT_PENDING", "EXIT_ALL_FAILED", "EXIT_SOME_BAD"]


EXIT_PENDING = 1
"""Exit status when points are still pending (interrupted, ``--max-points``)."""
EXIT_ALL_FAILED = 2
"""Exit status when every point failed (as for any error)."""
EXIT_SOME_BAD = 3
"""Exit status when every point has a record but some failed or did not complete."""


def cmd_sweep(args: argparse.Namespace) -> int:
    """Run (or resume) a sweep and return the exit status.

    0: every point ran and completed; :data:`EXIT_PENDING` (1): some points are still
    pending; :data:`EXIT_ALL_FAILED` (2): every point failed; :data:`EXIT_SOME_BAD` (3):
    some points failed, or ran but ended before their stop condition (``completed``
    false).  The table is written in every case.
    """
    from .._argtypes import print_json, progress_wanted
    from .engine import (
        default_point_function,
        default_workers,
        function_name,
        points_to_run,
        resolve_point_function,
        run_sweep,
    )
    from .spec import SweepError, load_sweep_spec
    from .store import RecordStore

    spec = load_sweep_spec(args.spec, validate_points=args.rtol is None)
    if args.rtol is not None:  # --rtol: [run] rtol of every point (validated by points())
        base = copy.deepcopy(spec.base)
        base.setdefault("run", {})["rtol"] = args.rtol
        spec = dataclasses.replace(spec, base=base, _points=[])
    points = spec.points()
    out = args.out if args.out is not None else Path.cwd() / f"{spec.name}-sweep"
    from ..files import check_output

    check_output(out, "dir")  # a file or a read-only place: refused before any point
    records = RecordStore(out / "records.jsonl").load()
    try:
        fname = function_name(resolve_point_function(
            args.point_function or default_point_function(spec)))
    except SweepError:
        if not args.dry_run:
            raise
        fname = None  # a dry run may go without the point function
    done = len(points) - len(points_to_run(points, records, fname, args.retry_failed))
    where = (f"scheduler {args.scheduler}" if args.scheduler else
             f"a local cluster of {args.workers or default_workers()} worker process(es)")
    shape = " x ".join(str(n) for n in spec.shape)
    msg = (f"sweep {spec.name!r}: {len(points)} points ({shape}, {spec.mode}); "
           f"{done} done before, {len(points) - done} to run on {where}; output {out}")
    if args.dry_run:
        if args.json:
            print_json({"name": spec.name, "n_points": len(points), "done": done,
                        "to_run": len(points) - done, "out": str(out),
                        "axes": [a.name for a in spec.axes]})
        else:
            print(msg)
        return 0
    if not args.json:
        print(msg, file=sys.stderr)
    try:
        outcome = run_sweep(spec, out=out, point_function=args.point_function,
                            workers=args.workers,
                            scheduler=args.scheduler, full_output=args.full_output,
                            retry_failed=args.retry_failed, max_points=args.max_points,
                            progress=progress_wanted(args),
                            consolidate_every=args.consolidate_every)
    except KeyboardInterrupt:
        print(f"\ninterrupted; finished points are kept in {out}. Run the same command "
              "again to compute only the rest.", file=sys.stderr)
        return 130
    if args.json:
        print_json(outcome.to_dict())
    else:
        print(f"{outcome.n_run} points run in {outcome.elapsed:.1f} s: table {outcome.table} "
              f"has {outcome.n_ok} ok, {outcome.n_failed} failed, {outcome.n_pending} pending")
    if outcome.n_lost:
        print(f"{outcome.n_lost} point(s) lost their worker (KilledWorker: it crashed or "
              "was killed, e.g. out of memory); they stay pending: rerun the same command "
              "to retry them", file=sys.stderr)
    full = _disk_full_points(out) if outcome.n_failed else []
    if full:
        print(f"hertzchain: error: disk full: {len(full)} point(s) could not write their "
              f"output under {out} ({full[0]}); free space and rerun with --retry-failed",
              file=sys.stderr)
    elif outcome.n_failed:
        print(f"{outcome.n_failed} point(s) failed (see the 'error' column); rerun with "
              "--retry-failed to retry them", file=sys.stderr)
    if outcome.n_incomplete:
        print(f"{outcome.n_incomplete} point(s) ended before their stop condition "
              "(column 'completed' false, the reason in 'incomplete_reason'): raise "
              "[run] max_steps or t_end in the sweep's base scenario", file=sys.stderr)
    if getattr(outcome, "n_unverified", 0):
        print(f"{outcome.n_unverified} point(s) are not verified to the rtol asked for "
              "(status 'unverified'; see the 'error' column)", file=sys.stderr)
    status = exit_status(outcome)
    if status == EXIT_ALL_FAILED and not full:
        print(f"hertzchain: error: every point of the sweep failed (table {outcome.table})",
              file=sys.stderr)
    return status


def _disk_full_points(out: Path) -> list[str]:
    """The errors of the failed points that are a full disk (from ``records.jsonl``)."""
    from ..faults import is_disk_full_text
    from .store import RecordStore

    records = RecordStore(Path(out) / "records.jsonl").load()
    return [r.get("error", "") for r in records.values()
            if r.get("status") == "failed" and is_disk_full_text(r.get("error", ""))]


def exit_status(outcome) -> int:
    """The exit status of ``hertzchain sweep`` for a :class:`SweepOutcome` (cmd_sweep)."""
    if outcome.n_pending:
        return EXIT_PENDING
    if outcome.n_points and outcome.n_failed == outcome.n_points:
        return EXIT_ALL_FAILED
    if outcome.n_failed or outcome.n_incomplete:
        return EXIT_SOME_BAD
    from ..measure import EXIT_NOT_VERIFIED  # (the one contract: docs/guide/exit_status.md)

    return EXIT_NOT_VERIFIED if getattr(outcome, "n_unverified", 0) else 0


def cmd_plot_sweep(args: argparse.Namespace) -> int:
    """Draw the phase-diagram map and cuts of a results table; print the agreement."""
    import numpy as np

    from .._argtypes import print_json
    from ..sweep_plot import save_sweep_figures
    from .analysis import classification_agreement
    from .store import read_results

    results = read_results(args.results)
    out = args.out
    if out is not None and out.suffix.lower() != ".png":  # a directory (docs/guide/cli.md)
        if out.exists() and not out.is_dir():
            raise FileExistsError(f"--out {out} is an existing file that is not a PNG; give "
                                  "a directory or a name ending in .png")
        out.mkdir(parents=True, exist_ok=True)
        out = out / "phase_map.png"
    written = save_sweep_figures(results, out, x=args.x, y=args.y, energy=args.energy)
    agreement = None
    if "alpha_rho" in results and np.isfinite(results["alpha_rho"]).any():
        agreement = classification_agreement(results)
    if args.json:
        print_json({"figures": [str(p) for p in written],
                    "agreement": agreement.to_dict() if agreement else None})
        return 0
    for path in written:
        print(f"wrote {path}")
    if agreement is not None and agreement.n_classified:
        print(agreement.summary())
    return 0


def shipped_sweep_names() -> list[str]:
    """Names of the sweeps shipped in ``hertzchain/sweeps`` (for ``--help``, NumPy-free).

    The same files as :func:`hertzchain.sweep.spec.shipped_sweeps` (a test compares them);
    listed here without importing the spec module, which imports NumPy.
    """
    folder = Path(__file__).resolve().parent.parent / "sweeps"
    return sorted(f.stem for f in folder.glob("*.toml"))


def add_sweep_parsers(subparsers) -> None:
    """Register ``sweep`` and ``plot-sweep`` on an ``add_subparsers()`` object."""
    p = subparsers.add_parser(
        "sweep", help="run a parameter sweep on Dask (resumable)",
        description="Run every point of a sweep file (a [base] scenario and [sweep] axes) "
        "on a Dask cluster and collect the run summaries in DIR/results.h5. Rerunning the "
        "same command computes only the points without a record.")
    p.add_argument("spec", metavar="SWEEP.toml", type=Path,
                   help="sweep specification, or the name of a shipped one ("
                   f"{', '.join(shipped_sweep_names())})")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=positive_int, default=None, metavar="N",
                       help="worker processes of the local cluster (default: all cores)")
    where.add_argument("--scheduler", metavar="ADDRESS", default=None,
                       help="address of an existing dask.distributed scheduler, e.g. "
                       "tcp://host:8786 (instead of a local cluster)")
    p.add_argument("--out", type=Path, default=None, metavar="DIR",
                   help="output directory (default ./<sweep name>-sweep)")
    p.add_argument("--full-output", action="store_true",
                   help="also write the full HDF5 file of every run (DIR/runs/<id>.h5)")
    p.add_argument("--retry-failed", action="store_true",
                   help="rerun points recorded as failed")
    p.add_argument("--max-points", type=positive_int, default=None, metavar="K",
                   help="stop after K points (resumable), e.g. to fit a batch time limit")
    p.add_argument("--point-function", default=None, metavar="MODULE:FUNC",
                   help="function run per point (default hertzchain.runner:run_scenario, the "
                        "discrete chain; with [base.models] in the sweep: "
                        "hertzchain.compare:compare_point, every model compared)")
    p.add_argument("--consolidate-every", type=positive_float, default=30.0, metavar="S",
                   help="seconds between rewrites of results.h5 while running (default 30)")
    from ..cli import add_rtol_argument

    add_rtol_argument(p)
    from .._argtypes import add_progress_argument

    add_progress_argument(p)
    p.add_argument("--dry-run", action="store_true",
                   help="validate every point and report what would run")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=cmd_sweep)

    q = subparsers.add_parser(
        "plot-sweep", help="phase-diagram map and 1-D cuts of a sweep's results",
        description="Draw the classification map with the theory lines gamma_c0 = 1 and "
        "gamma_RG = 1 and reflected-energy contours, plus 1-D cuts; print how well the "
        "classification agrees with theory.")
    q.add_argument("results", metavar="RESULTS", type=Path,
                   help="results.h5 or the sweep's output directory")
    q.add_argument("--out", type=Path, default=None, metavar="OUT",
                   help="a directory (OUT/phase_map.png) or the map's name ending in .png "
                   "(default RESULTS_DIR/phase_map.png; the cuts go beside it, *-cuts.png)")
    q.add_argument("--x", default=None, help="column on the x axis (default alpha_rho)")
    q.add_argument("--y", default=None, help="column on the y axis (default alpha_kn)")
    q.add_argument("--energy", default="Ek_re", choices=["Ek_re", "Ep_re", "Et_re"],
                   help="reflected-energy ratio to contour (default Ek_re)")
    q.add_argument("--json", action="store_true", help="print one JSON object")
    q.set_defaults(func=cmd_plot_sweep)


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m hertzchain.sweep {sweep,plot-sweep} ...``; returns the exit status.

    Errors are handled as by ``hertzchain`` itself (:func:`hertzchain.cli.run_command`).
    """
    from ..cli import run_command

    parser = argparse.ArgumentParser(prog="python -m hertzchain.sweep")
    add_sweep_parsers(parser.add_subparsers(dest="command", metavar="COMMAND", required=True))
    args = parser.parse_args(argv)
    return run_command(args, whole_process=argv is None)
