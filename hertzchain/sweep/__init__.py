"""Parameter sweeps on Dask: many scenarios, one results table, a phase-diagram map.

A sweep is a base scenario and axes of values at dotted paths into it (see
:mod:`hertzchain.sweep.spec` for the TOML format).  :func:`run_sweep` runs the missing
points on a Dask cluster and writes ``results.h5`` (:mod:`hertzchain.sweep.store`);
:func:`classification_agreement` compares the measured classification with the theory
regions of the paper's Fig. 7; :mod:`hertzchain.sweep_plot` draws the map.

Examples
--------
>>> from hertzchain.sweep import load_sweep_spec, run_sweep, read_results
>>> spec = load_sweep_spec("fig7_map")        # a shipped sweep, or a path  # doctest: +SKIP
>>> outcome = run_sweep(spec, out="fig7-sweep", workers=2)       # doctest: +SKIP
>>> table = read_results(outcome.table)                          # doctest: +SKIP
"""

from .analysis import Agreement, classification_agreement, fission_parameter, predicted_labels
from .cli import add_sweep_parsers
from .engine import (
    DEFAULT_POINT_FUNCTION,
    SweepOutcome,
    default_workers,
    resolve_point_function,
    run_point,
    run_sweep,
    tiny_scenario,
)
from .spec import (
    Axis,
    Point,
    SweepError,
    SweepSpec,
    load_sweep_spec,
    parse_sweep_spec,
    shipped_sweeps,
)
from .store import SUMMARY_FIELDS, RecordStore, SweepResults, read_results, write_table

__all__ = [
    "Agreement",
    "Axis",
    "DEFAULT_POINT_FUNCTION",
    "Point",
    "RecordStore",
    "SUMMARY_FIELDS",
    "SweepError",
    "SweepOutcome",
    "SweepResults",
    "SweepSpec",
    "add_sweep_parsers",
    "classification_agreement",
    "default_workers",
    "fission_parameter",
    "load_sweep_spec",
    "parse_sweep_spec",
    "predicted_labels",
    "read_results",
    "resolve_point_function",
    "run_point",
    "run_sweep",
    "shipped_sweeps",
    "tiny_scenario",
    "write_table",
]
