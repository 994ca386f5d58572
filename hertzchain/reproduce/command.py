"""Arguments and output of ``hertzchain reproduce`` (registered in :mod:`hertzchain.cli`).

Kept free of heavy imports: the solvers are imported only when the command runs.
"""

from __future__ import annotations

import argparse
import sys

from .._argtypes import (
    add_checkpoint_argument,
    add_progress_argument,
    positive_int,
    print_json,
    progress_wanted,
)
from . import ITEMS, check_items

__all__ = ["add_arguments", "run_command"]


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``hertzchain reproduce``."""
    p.add_argument("items", nargs="*", metavar="ITEM",
                   help=f"what to reproduce, among {', '.join(ITEMS)} (default: all)")
    size = p.add_mutually_exclusive_group()
    size.add_argument("--quick", dest="mode", action="store_const", const="quick",
                      help="reduced sizes, all items in a few minutes (default)")
    size.add_argument("--full", dest="mode", action="store_const", const="full",
                      help="the paper's sizes (Fig. 5: 50,000 grains; denser Figs. 6, 7)")
    p.set_defaults(mode="quick")
    p.add_argument("--out", default="hertzchain-reproduce", metavar="DIR",
                   help="output directory (runs/*.h5, figures/*.png, report.md, report.html;"
                   " default ./hertzchain-reproduce)")
    p.add_argument("--json", action="store_true",
                   help="print the items' numbers as one JSON object (keyed by item if "
                        "several)")
    p.add_argument("--force", action="store_true",
                   help="recompute every simulation even if its HDF5 file exists "
                        "(discards checkpoints)")
    p.add_argument("--workers", type=positive_int, default=None, metavar="N",
                   help="processes running the items' tasks at once, each on one core "
                        "(the same numbers, bit for bit, for every N; default: the "
                        "machine's cores); 1 runs them one after the other in this "
                        "process")
    add_checkpoint_argument(p, "of a simulation, s (>= 0; default 300; beside its file in "
                            "OUT/runs). Rerunning the same command reuses the finished "
                            "simulations and resumes the interrupted one from its last "
                            "checkpoint, bit for bit; Ctrl-C stops with a checkpoint")

    add_progress_argument(p)



def _text(result: dict) -> str:
    from .report import summary_rows

    lines = []
    for q, ours, paper, diff, note in summary_rows(result["runs"]):
        text = f"{q}: {ours}" if paper == "—" else f"{q}: ours {ours}, paper {paper}"
        text += f", difference {diff}" if diff != "—" else ""
        lines.append(text + (f" ({note})" if note else ""))
    if "table2" in result["items"]:
        from ..paper import TABLE2, TABLE2_KEYS

        lines.append("Table 2 (discrete; paper in brackets):")
        lines.append("       " + "".join(f"{k:>20}" for k in TABLE2_KEYS))
        for point, row in result["items"]["table2"].items():
            lines.append(f"  {point}    " + "".join(
                f"{row[k]:>10.5f} ({TABLE2[point][k]:>7.5f})" for k in TABLE2_KEYS))
    ctx = result["context"]
    lines.append(f"{len(ctx.computed)} simulations computed, {len(ctx.reused)} reused; "
                 f"wall time {result['wall_time']:.0f} s")
    if result["compile_seconds"] >= 0.5:  # a cold kernel cache: say what it cost
        lines.append(f"numba spent {result['compile_seconds']:.0f} s of CPU compiling kernels "
                     "(the first run after installing or after a change of the code; "
                     "cached afterwards; with several workers the sum over them, "
                     "which compile at the same time)")
    for p in result["report"]:
        lines.append(f"written: {p}")
    return "\n".join(lines)


def run_command(args: argparse.Namespace) -> int:
    """Run ``hertzchain reproduce``; print JSON or a short summary; return the exit status."""
    from ..checkpoint import Interrupted
    from . import reproduce

    items = check_items(args.items)  # ValueError → "hertzchain: error: ..." (exit 2)
    try:
        result = reproduce(items, mode=args.mode, out=args.out, force=args.force,
                           progress=progress_wanted(args),
                           checkpoint_interval=args.checkpoint_interval,
                           workers=args.workers)
    except Interrupted:  # during a simulation: the message says how to resume
        raise
    except KeyboardInterrupt:  # between simulations (set-up, analysis, figures)
        print("hertzchain: interrupted; the finished simulations are kept in "
              f"{args.out}/runs: rerun the same command to continue", file=sys.stderr)
        return 130
    if args.json:
        nums = result["items"]
        out = nums[items[0]] if len(items) == 1 else nums
        print_json(out)
    else:
        print(_text(result))
    return 0
