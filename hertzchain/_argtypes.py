"""argparse ``type=`` converters that name the allowed range in their error."""

from __future__ import annotations

import argparse
import math

__all__ = ["positive_float", "nonnegative_float", "positive_int", "scenario_number"]


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
