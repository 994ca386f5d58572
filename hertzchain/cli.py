"""The ``hertzchain`` command-line tool.

Each sub-command lives in its own function ``cmd_<name>`` and is registered in
:func:`build_parser`; ``main`` returns the process exit status.
"""

from __future__ import annotations

import argparse
import errno
import gc
import json
import os
import sys
from collections.abc import Sequence
from pathlib import Path

from ._argtypes import nonnegative_float, positive_float, positive_int, scenario_number

__all__ = ["main", "build_parser"]


def cmd_theory(args: argparse.Namespace) -> int:
    """Print the linear-acoustic interface predictions for (α_ρ, α_kn)."""
    import theory

    pred = theory.predict(args.alpha_rho, args.alpha_kn)
    out = pred.to_dict()
    if args.delta0 is not None and args.delta0 > 0:
        mat = theory.PAPER_MATERIAL
        d = args.diameter
        m = theory.grain_mass(d, mat.density)
        k = theory.hertz_constant(d, mat)
        c0l = theory.c0(k, m, d, args.delta0 * d)
        out["delta0_over_d_left"] = args.delta0
        out["delta0_over_d_right"] = args.delta0 * pred.delta0_ratio
        out["c0_left_m_per_s"] = c0l
        out["c0_right_m_per_s"] = c0l * pred.gamma_c0
        out["material_left"] = mat.name
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    width = max(len(k) for k in out)
    print("Interface predictions (paper Eqs. 9, 12, 13; linear acoustics)")
    for key, value in out.items():
        text = f"{value:.6g}" if isinstance(value, float) else str(value)
        print(f"  {key:<{width}}  {text}")
    return 0


def _json_default(obj):
    import numpy as np

    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(type(obj).__name__)


def _with_rtol(scenario, rtol: float | None):
    """The scenario with ``[run] rtol`` set from ``--rtol`` (None: unchanged)."""
    return scenario if rtol is None else scenario.with_values({"run.rtol": rtol})


def add_rtol_argument(p: argparse.ArgumentParser) -> None:
    """``--rtol``: the relative accuracy of the discrete run (``[run] rtol``)."""
    p.add_argument("--rtol", type=positive_float, default=None, metavar="R",
                   help="relative accuracy of the recorded quantities, in (0, 1): dt chosen "
                   "from a step-doubling probe (overrides [run] rtol; an explicit [run] dt "
                   "wins)")


def cmd_run(args: argparse.Namespace) -> int:
    """Run every model of a scenario TOML file (:func:`hertzchain.models.run`), print a summary.

    With ``--out`` the discrete run is written there (checkpointed to ``OUT.ckpt`` every
    ``--checkpoint-interval`` seconds of wall time; rerunning the same command resumes
    from it, bit for bit; ``--restart`` discards it) and a continuum beside it
    (``OUT`` with the suffix ``.continuum.h5``).

    Exit status 0 when every model completed; 2 on an error (invalid scenario,
    unreachable stop, instability, I/O); :data:`EXIT_INCOMPLETE` (3) when a run ended
    before the stop the scenario asked for (``completed`` false: ``max_steps`` came
    first, a snapshot was never taken, or the continuum failed);
    :data:`EXIT_NOT_VERIFIED` (4) when it completed but its kinetic/potential split is
    not verified to the rtol asked for (``split_meets_rtol`` false) — the summary is
    printed and written all the same.
    """
    from .checkpoint import OutputWriteError
    from .files import check_output
    from .models import run
    from .scenario import load_scenario

    scenario = _with_rtol(load_scenario(args.scenario), args.rtol)
    out = args.out
    if out is not None:  # a read-only place or a directory: refused before the run
        check_output(out, "file")
        if scenario.models.continuum:  # written beside it
            check_output(Path(out).with_suffix(".continuum.h5"), "file")

    def log(message: str) -> None:
        print(f"hertzchain: {message}", file=sys.stderr, flush=True)

    try:
        result = run(scenario, out=out, progress=not args.json,
                     checkpoint_interval=args.checkpoint_interval, resume=not args.restart,
                     threads=args.threads, log=log)
    except OutputWriteError as exc:  # finished, but the file failed: show what was found
        _print_summary(scenario, args, exc.summary)
        print(f"hertzchain: error: {exc}", file=sys.stderr)
        return 2
    summary = result.summary()
    _print_summary(scenario, args, summary)
    if not args.json:
        for path in (out, getattr(result.continuum, "path", None)):
            if path:
                print(f"written: {path}")
    status = _incomplete_status(summary, out)
    if summary.get("split_meets_rtol") is False:
        status = status or EXIT_NOT_VERIFIED
        print(f"hertzchain: error: the kinetic/potential split Ek_*/Ep_* is not verified "
              f"to rtol = {summary['rtol']:g} (its estimated error split_estimate = "
              f"{summary['split_estimate']:.2g}); Et_* and the other quantities are "
              "(the split's windows need the waves separated and away from the chain's "
              "ends: docs/physics.md §6)",
              file=sys.stderr)
    failed = [m for m in result.models if m.name != "discrete" and not m.completed]
    for m in failed:
        print(f"hertzchain: error: the {m.name} model did not complete: {m.stopped_by}",
              file=sys.stderr)
    return EXIT_INCOMPLETE if failed else status


def _print_summary(scenario, args: argparse.Namespace, summary: dict) -> None:
    """The summary of ``hertzchain run``: one JSON object, or a table."""
    if args.json:
        print(json.dumps(summary, default=_json_default, allow_nan=True))
        return
    print(f"scenario {scenario.name or args.scenario}: {scenario.chain.n} grains; "
          f"models: {', '.join(scenario.models.names)}")
    for key, value in summary.items():
        text = (f"{value:.6g}" if isinstance(value, float)
                else "n/a" if value is None else str(value))
        print(f"  {key:<26} {text}")


def cmd_compare(args: argparse.Namespace) -> int:
    """Run every model of a scenario and compare them (:mod:`hertzchain.compare`).

    Writes ``OUT/compare.h5``, the figures and ``OUT/report.md``/``.html`` (the runs are
    cached in ``OUT/runs``); prints the verdict and the differences, or with ``--json``
    every number.  Exit status :data:`EXIT_INCOMPLETE` (3) if a model did not complete
    (it is not compared).
    """
    from .compare import compare
    from .files import check_output
    from .reproduce.command import jsonable
    from .scenario import load_scenario

    scenario = _with_rtol(load_scenario(args.scenario), args.rtol)
    check_output(args.out, "dir")  # before the runs, not after them
    _clean_caches(Path(args.out) / "runs", args.force)
    if args.continuum is not None:
        scenario = scenario.with_values(
            {"models.continuum": False if args.continuum == "off" else args.continuum})

    def log(message: str) -> None:
        print(f"hertzchain: {message}", file=sys.stderr, flush=True)

    cmp = compare(scenario, out=args.out, force=args.force, progress=not args.json,
                  checkpoint_interval=args.checkpoint_interval, threads=args.threads,
                  log=log)
    if args.json:
        print(json.dumps(jsonable(cmp.to_dict()), allow_nan=False))
    else:
        from .compare_output import difference_rows

        print(cmp.verdict())
        for row in difference_rows(cmp):
            print("  " + " | ".join(row))
        print(f"written: {args.out}/compare.h5, figures, report.md, report.html")
    failed = [m for m in cmp.run.models if not m.completed]
    for m in failed:
        print(f"hertzchain: error: the {m.name} model did not complete ({m.stopped_by}); "
              "it is not compared", file=sys.stderr)
    return EXIT_INCOMPLETE if failed else 0


EXIT_INCOMPLETE = 3
"""Exit status of a run that ended before the stop the scenario asked for."""

EXIT_NOT_VERIFIED = 4
"""Exit status of a run that reached its stop but whose kinetic/potential split is not
verified to the ``rtol`` it asked for (summary ``split_meets_rtol`` false)."""


def _incomplete_status(summary: dict, out) -> int:
    """0, or :data:`EXIT_INCOMPLETE` with a message if the run did not complete."""
    if summary.get("completed", True):
        return 0
    kept = f"; its results are in {out} (completed = false)" if out else ""
    print(f"hertzchain: error: incomplete run: {summary['incomplete_reason']}{kept}. Raise "
          "[run] max_steps or t_end, or move the stop or snapshots within reach",
          file=sys.stderr)
    return EXIT_INCOMPLETE


def cmd_info(args: argparse.Namespace) -> int:
    """Describe an HDF5 file written by either solver."""
    from .files import describe

    print(describe(args.file))
    return 0


def cmd_plot(args: argparse.Namespace) -> int:
    """Plot an HDF5 result file to PNG."""
    from .files import plot_file

    out = plot_file(args.file, args.out)
    print(f"written: {out}")
    return 0


def cmd_reproduce(args: argparse.Namespace) -> int:
    """Reproduce the paper's figures and Table 2 (:mod:`hertzchain.reproduce`)."""
    from .files import check_output
    from .reproduce.command import run_command

    if getattr(args, "out", None) is not None:
        check_output(args.out, "dir")  # before the runs, not after them
        for sub in ("runs", "cache"):
            _clean_caches(Path(args.out) / sub, getattr(args, "force", False))
    return run_command(args)


def _clean_caches(directory: Path, force: bool) -> None:
    """Remove killed writers' temporaries; with ``--force`` also the settled waves."""
    from .cache import clear_settled_waves, remove_stale_temporaries

    for p in remove_stale_temporaries(directory):
        print(f"hertzchain: removed {p}, left by a killed writer", file=sys.stderr)
    if force:
        for p in clear_settled_waves(directory):
            print(f"hertzchain: removed the settled wave {p} (--force)", file=sys.stderr)


class _VersionAction(argparse.Action):
    """``--version``: the installed version, read only when asked for (start-up)."""

    def __call__(self, parser, namespace, values, option_string=None):
        from . import __version__

        print(f"hertzchain {__version__}")  # on stdout, as argparse's "version" action
        parser.exit()


def build_parser() -> argparse.ArgumentParser:
    """Build the argument parser with every sub-command."""
    parser = argparse.ArgumentParser(
        prog="hertzchain",
        description="Solitary waves in Hertzian granular chains: discrete (DEM), "
        "continuum (long-wave) and closed-form theory, side by side.",
    )
    from .scenario import schema_key

    parser.add_argument("--version", action=_VersionAction, nargs=0,
                        help="show program's version number and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    p = sub.add_parser("theory", help="interface predictions for (alpha_rho, alpha_kn)")
    p.add_argument("--alpha-rho", type=positive_float, required=True,
                   help="density ratio rho_R/rho_L (> 0)")
    p.add_argument("--alpha-kn", type=positive_float, required=True,
                   help="contact-stiffness ratio k_n^R/k_n^L (> 0)")
    d0_key = schema_key("chain", "delta0_over_d")
    p.add_argument("--delta0", type=scenario_number("chain", "delta0_over_d"),
                   default=None, help="left-section precompression delta0/d (dimensionless, "
                   f"range {d0_key.range_text()}: [chain] delta0_over_d of a scenario)")
    p.add_argument("--diameter", type=scenario_number("chain", "diameter"),
                   default=5e-3, help="grain diameter in m (> 0; default 5e-3, the paper's)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=cmd_theory)

    p = sub.add_parser("run", help="run a scenario TOML file (the models of its [models] "
                       "table)")
    p.add_argument("scenario", help="scenario file (see hertzchain/scenarios/*.toml)")
    p.add_argument("--out", default=None, help="write the full run to this HDF5 file "
                   "(atomically; checkpoints go to OUT.ckpt)")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.add_argument("--checkpoint-interval", type=nonnegative_float, default=300.0,
                   metavar="SECONDS", help="wall time between checkpoints with --out, s "
                   "(>= 0; default 300). Rerunning the same command resumes from the last "
                   "checkpoint, bit for bit; Ctrl-C stops with a checkpoint")
    p.add_argument("--restart", action="store_true",
                   help="discard an existing checkpoint of --out and start over")
    add_rtol_argument(p)
    p.add_argument("--threads", type=positive_int, default=None, metavar="N",
                   help="kernel threads (>= 1; default: numba's; results are identical)")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("compare", help="run the discrete chain, the continuum and the "
                       "theory of a scenario side by side and compare them")
    p.add_argument("scenario", help="scenario file (or the name of a shipped one, see "
                   "hertzchain/scenarios/)")
    p.add_argument("--out", default="hertzchain-compare",
                   help="output directory (compare.h5, figures, report.md, runs/)")
    p.add_argument("--json", action="store_true", help="print every number as JSON")
    p.add_argument("--continuum", default=None,
                   choices=("auto", "eq4", "eq7", "kdv", "off"),
                   help="override [models] continuum (default: the scenario's)")
    p.add_argument("--force", action="store_true",
                   help="recompute the runs even if cached in OUT/runs")
    p.add_argument("--checkpoint-interval", type=nonnegative_float, default=300.0,
                   metavar="SECONDS", help="wall time between checkpoints of the discrete "
                   "run, s (>= 0; default 300); rerunning resumes from the last one")
    add_rtol_argument(p)
    p.add_argument("--threads", type=positive_int, default=None, metavar="N",
                   help="kernel threads of the discrete solver (>= 1)")
    p.set_defaults(func=cmd_compare)

    from .reproduce.command import add_arguments as reproduce_arguments

    p = sub.add_parser("reproduce", help="reproduce the paper's Figs. 2-8 and Table 2")
    reproduce_arguments(p)
    p.set_defaults(func=cmd_reproduce)

    p = sub.add_parser("info", help="describe an HDF5 result file")
    p.add_argument("file")
    p.set_defaults(func=cmd_info)

    p = sub.add_parser("plot", help="plot an HDF5 result file to PNG")
    p.add_argument("file")
    p.add_argument("--out", default=None, help="PNG path (default: beside the file)")
    p.set_defaults(func=cmd_plot)

    from .sweep import add_sweep_parsers

    add_sweep_parsers(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments without the program name.  None (the ``hertzchain`` console
        script, ``python -m hertzchain``) reads ``sys.argv`` and means that the process
        ends when ``main`` returns: the garbage collector's youngest generation is then
        collected every :data:`GC_THRESHOLD0` allocations, and everything alive is
        frozen (:func:`gc.freeze`) when ``main`` returns, so that the interpreter's
        collections at exit skip the ~10^5 objects of the imports (NumPy, numba,
        SciPy), which the operating system reclaims anyway: much of a small run's
        CPU time (docs/benchmarks.md, "Start-up of a small run").  A caller passing
        ``argv`` (tests, scripts) keeps its collector as it was.

    Returns
    -------
    int
        The exit status.
    """
    whole_process = argv is None
    if whole_process:
        gc.set_threshold(GC_THRESHOLD0, *gc.get_threshold()[1:])
    try:
        return _main(argv)
    finally:
        if whole_process:
            gc.freeze()


GC_THRESHOLD0 = 20_000
"""Young-generation threshold (allocations) of a process that is one ``hertzchain``
command (CPython's default is 700): numba's first kernel load creates ~10^5 long-lived
objects, over which young collections would pass again and again.  Cyclic garbage is
still freed, at most this many allocations later."""


def _main(argv: Sequence[str] | None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if getattr(args, "func", None) is None:
        parser.print_help()
        return 0
    from discrete import InstabilityError
    from theory.jitcache import announce_compilation

    from .checkpoint import Interrupted

    try:
        with announce_compilation():  # a cold kernel cache is announced before compiling
            return int(args.func(args) or 0)
    except BrokenPipeError:  # output piped into e.g. `head`
        return 0
    except (ValueError, OSError, InstabilityError) as exc:  # incl. FileNotFoundError
        print(f"hertzchain: error: {exc}", file=sys.stderr)
        if isinstance(exc, OSError) and exc.errno in (errno.ENOSPC, errno.EFBIG):
            # a failed HDF5 write can leave h5py objects that crash the interpreter
            # when they are freed (a segfault after the message): leave at once
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(2)
        return 2
    except Interrupted as exc:  # SIGINT/SIGTERM during a checkpointed run
        print(f"hertzchain: {exc}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print("hertzchain: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
