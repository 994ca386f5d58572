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

import importlib

# Names are imported from their submodules when first used (PEP 562): the CLI needs
# only ``add_sweep_parsers`` to build its parser, and must not pay for h5py, Dask and
# the store when it runs something else (the start-up of ``hertzchain run``).
_WHERE = {
    "Agreement": "analysis", "classification_agreement": "analysis",
    "fission_parameter": "analysis", "predicted_labels": "analysis",
    "add_sweep_parsers": "cli",
    "DEFAULT_POINT_FUNCTION": "engine", "SweepOutcome": "engine",
    "default_workers": "engine", "resolve_point_function": "engine", "run_point": "engine",
    "run_sweep": "engine", "tiny_scenario": "engine",
    "Axis": "spec", "EnsembleSpec": "spec", "Point": "spec", "SweepError": "spec",
    "SweepSpec": "spec",
    "load_sweep_spec": "spec", "parse_sweep_spec": "spec", "shipped_sweeps": "spec",
    "SUMMARY_FIELDS": "store", "RecordStore": "store", "SweepResults": "store",
    "read_results": "store", "write_table": "store",
}


def __getattr__(name: str):
    where = _WHERE.get(name)
    if where is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{where}"), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_WHERE))


__all__ = [
    "Agreement",
    "Axis",
    "DEFAULT_POINT_FUNCTION",
    "EnsembleSpec",
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
