"""What every subcommand shares.

argparse ``type=`` converters that name the allowed range in their error, the
``--no-progress`` flag and its rule, and strict JSON output.
"""

from __future__ import annotations

import argparse
import json
import math
import sys

__all__ = ["positive_float", "nonnegative_float", "positive_int", "scenario_number",
           "add_progress_argument", "add_checkpoint_argument", "add_threads_argument",
           "progress_wanted", "jsonable", "print_json"]


def _float(text: str) -> float:
    try:
        value = float(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from exc
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
    return value


def positive_float(text: str) -> float:
    """A finite float > 0."""
    value = _float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return value


def nonnegative_float(text: str) -> float:
    """A finite float >= 0."""
    value = _float(text)
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0, got {text!r}")
    return value


def positive_int(text: str) -> int:
    """An integer >= 1."""
    try:
        value = int(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from exc
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be an integer >= 1, got {text!r}")
    return value


def scenario_number(table: str, name: str):
    """A converter for a flag that mirrors the scenario key ``[table] name``.

    The value is checked against the key's range in :data:`hertzchain.scenario.SCHEMA`
    (the one definition), so the flag and the scenario file accept the same numbers.
    """
    from .scenario import ScenarioError, read_key, schema_key

    key = schema_key(table, name)

    def convert(text: str) -> float:
        value = _float(text)
        try:
            return read_key(table, name, value)
        except ScenarioError as exc:
            raise argparse.ArgumentTypeError(
                f"must be in {key.range_text()} (the range of the scenario key "
                f"[{table}] {name}), got {text!r}") from exc

    convert.__name__ = name  # argparse names the converter in some messages
    return convert


def add_checkpoint_argument(p: argparse.ArgumentParser, what: str) -> None:
    """``--checkpoint-interval``: wall time between checkpoints, s (>= 0, default 300).

    ``what`` is the help text after the common part (where they go, how a rerun resumes).
    """
    p.add_argument("--checkpoint-interval", type=nonnegative_float, default=300.0,
                   metavar="SECONDS", help="wall time between checkpoints " + what)


def add_threads_argument(p: argparse.ArgumentParser, what: str) -> None:
    """``--threads``: kernel threads of the discrete solver (>= 1; results identical)."""
    p.add_argument("--threads", type=positive_int, default=None, metavar="N", help=what)


def add_progress_argument(p: argparse.ArgumentParser) -> None:
    """``--no-progress``: no progress bars (every command that shows them)."""
    p.add_argument("--no-progress", action="store_true",
                   help="no progress bars on stderr (--json implies it unless stderr is a "
                   "terminal)")


def progress_wanted(args: argparse.Namespace) -> bool:
    """Progress bars on stderr: unless ``--no-progress``; with ``--json`` only on a terminal.

    (The bars never touch stdout, so ``--json`` output stays one JSON document.)
    """
    if getattr(args, "no_progress", False):
        return False
    return not getattr(args, "json", False) or sys.stderr.isatty()


def jsonable(obj):
    """Plain JSON types (NaN/inf → None, numpy scalars → Python, tuples → lists)."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [jsonable(v) for v in obj]
    if hasattr(obj, "item") and not isinstance(obj, str | bytes):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def print_json(obj) -> None:
    """Print ``obj`` as strict JSON: NaN and ±inf become null (never ``NaN``/``Infinity``)."""
    print(json.dumps(jsonable(obj), allow_nan=False))
