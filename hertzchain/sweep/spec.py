"""Sweep specifications: a base scenario and the axes along which it varies.

A sweep file is TOML with a ``[base]`` scenario (the schema of
:mod:`hertzchain.scenario`) and a ``[sweep]`` table::

    name = "fig7"                          # optional label (default: the file stem)
    description = "free text"              # optional

    [base]                                 # a complete scenario
    [base.chain]
    delta0_over_d = 1e-3
    [[base.chain.sections]]
    n = 200
    [[base.chain.sections]]
    n = 550
    # ... [base.initial], [base.run], [base.record]

    [sweep]
    mode = "product"                       # "product" (default): Cartesian product of
                                           # the axes; "zip": point i takes value i of
                                           # every axis (an explicit list of points)
    [[sweep.axes]]
    path = "chain.sections.1.alpha_rho"    # dotted path into the scenario; list
                                           # entries by 0-based index
    name = "alpha_rho"                     # optional column name (default: the path)
    logspace = [0.2, 5.0, 21]              # n values geometrically spaced from lo to hi
                                           # (the values themselves, not exponents);
                                           # or linspace = [lo, hi, n]; or values = [...]
    integer = false                        # round the values to integers (e.g. for
                                           # chain.sections.0.n)

    [ensemble]                             # optional: realisations of the disorder
    seeds = 256                            # seeds first_seed .. first_seed + seeds - 1
    path = "chain.sections.0.seed"         # default: the seed of the one disordered
                                           # section of [base]
    first_seed = 0                         # optional
    batch = 64                             # realisations per Dask task (default 64)

    [[sweep.axes]]                         # product mode: a linked axis moves with an
    path = "initial.strain_max"            # earlier one (value i with its value i): one
    with = "delta0"                        # dimension of the product sets several keys
    values = [1e-6, 9e-4, 1e-3]            # (same number of values; its own column)

An ``[ensemble]`` table adds the seed axis ``seed`` (last, product mode): every point of
the other axes becomes ``seeds`` realisations of its disorder, each a point (a row) of
its own, run in batches of ``batch`` realisations integrated together
(:mod:`hertzchain.sweep.ensemble`); ``[sweep]`` may then have no axes of its own.

Every point of the sweep is a scenario: the base with the axis values substituted at
their paths, validated by :func:`~hertzchain.scenario.parse_scenario` before anything
runs.  A point's id is :func:`~hertzchain.cache.param_hash` of its validated scenario,
so two sweeps that share points share their results.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..cache import canonical_json, param_hash
from ..scenario import Scenario, ScenarioError, parse_scenario, read_toml

__all__ = [
    "SweepError",
    "Axis",
    "EnsembleSpec",
    "Point",
    "SweepSpec",
    "RESERVED_COLUMNS",
    "load_sweep_spec",
    "parse_sweep_spec",
    "set_path",
    "shipped_sweeps",
]

RESERVED_COLUMNS = frozenset({
    "id", "index", "status", "error", "point_wall_time", "worker", "full_output",
    "point_function",
    "alpha_rho", "alpha_kn", "delta0_over_d", "gamma_c0", "gamma_RG", "theory_region",
})
"""Column names of the results table that an axis ``name`` may not take."""

_MAX_REPORTED = 5

MAX_POINTS = 1_000_000
"""Most points a sweep may have (each is a full simulation): an axis of 1e9 values would
allocate GBs before anything is reported."""


class SweepError(ScenarioError):
    """A sweep specification (or one of its points) is invalid; the message names the key."""


@dataclass(frozen=True)
class Axis:
    """One swept parameter.

    Parameters
    ----------
    path : str
        Dotted path into the scenario table, e.g. ``"chain.sections.1.alpha_rho"``.
    name : str
        Column name in the results table.
    values : tuple
        The values, in order (numbers, strings or booleans).
    follows : str
        Product mode: the name of an earlier axis this one is linked to (its value i goes
        with that axis's value i, so it adds no dimension); "" for an independent axis.
    """

    path: str
    name: str
    values: tuple
    follows: str = ""


@dataclass(frozen=True)
class EnsembleSpec:
    """The ``[ensemble]`` table: realisations of the disorder along a seed axis.

    Parameters
    ----------
    seeds : int
        Realisations per point of the other axes (>= 1).
    path : str
        Dotted path of the seed in the scenario, e.g. ``"chain.sections.0.seed"``.
    first_seed : int
        The first seed (>= 0); the seeds are ``first_seed .. first_seed + seeds - 1``.
    batch : int
        Realisations per Dask task, integrated together (>= 1).
    """

    seeds: int
    path: str
    first_seed: int = 0
    batch: int = 64

    name = "seed"
    """Column name of the seed axis."""

    def axis(self) -> Axis:
        """The seed axis the ensemble adds to the sweep."""
        return Axis(path=self.path, name=self.name,
                    values=tuple(range(self.first_seed, self.first_seed + self.seeds)))

    def to_dict(self) -> dict:
        """JSON-able description."""
        return {"seeds": self.seeds, "path": self.path, "first_seed": self.first_seed,
                "batch": self.batch}


@dataclass(frozen=True)
class Point:
    """One point of a sweep: its position, its axis values and its validated scenario."""

    index: int
    values: dict[str, Any]
    scenario: Scenario
    id: str

    def label(self) -> str:
        """Short human-readable ``name=value`` list."""
        return ", ".join(f"{k}={v!r}" for k, v in self.values.items())


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep: base scenario table, mode and axes.

    Use :func:`load_sweep_spec` or :func:`parse_sweep_spec` to build one; ``points()``
    expands and validates every point (and is cached).
    """

    name: str
    base: dict
    axes: tuple[Axis, ...]
    mode: str = "product"
    description: str = ""
    ensemble: EnsembleSpec | None = None
    _points: list = field(default_factory=list, repr=False, compare=False)

    @property
    def shape(self) -> tuple[int, ...]:
        """Number of values per independent axis (product mode) or ``(n_points,)`` (zip)."""
        if self.mode == "zip":
            return (len(self.axes[0].values),)
        return tuple(len(a.values) for a in self.axes if not a.follows)

    @property
    def n_points(self) -> int:
        """Total number of points."""
        return math.prod(self.shape)

    def to_dict(self) -> dict:
        """Plain JSON-able description (stored with the results)."""
        ens = self.ensemble
        out = {
            "name": self.name,
            "description": self.description,
            "mode": self.mode,
            "base": self.base,
            "axes": [{"path": a.path, "name": a.name, "values": list(a.values)}
                     | ({"with": a.follows} if a.follows else {}) for a in self.axes
                     if ens is None or a.name != ens.name],
        }
        if ens is not None:  # (its seed axis is the last of ``axes``)
            out["ensemble"] = ens.to_dict()
        return out

    def to_json(self) -> str:
        """Canonical JSON text of :meth:`to_dict`."""
        return canonical_json(self.to_dict())

    def point_table(self, values: dict[str, Any]) -> dict:
        """The raw scenario table of a point: the base with ``values`` (by axis name) set."""
        table = copy.deepcopy(self.base)
        for axis in self.axes:
            set_path(table, axis.path, values[axis.name])
        return table

    def points(self) -> list[Point]:
        """All points in order, each validated through ``parse_scenario``.

        Raises
        ------
        SweepError
            If any point is not a valid scenario (the first few are named) or two
            points are the same scenario.
        """
        if self._points:
            return self._points
        lead = [a for a in self.axes if not a.follows]
        combos = (zip(*(a.values for a in self.axes), strict=True) if self.mode == "zip"
                  else _product([tuple(range(len(a.values))) for a in lead]))
        points, bad, seen = [], [], {}
        for i, combo in enumerate(combos):
            if self.mode == "zip":
                values = {a.name: v for a, v in zip(self.axes, combo, strict=True)}
            else:  # value indices of the independent axes; a linked one takes its leader's
                at = {a.name: j for a, j in zip(lead, combo, strict=True)}
                values = {a.name: a.values[at[a.follows or a.name]] for a in self.axes}
            try:
                scenario = parse_scenario(self.point_table(values))
            except ScenarioError as exc:
                bad.append(f"point {i} ({_label(values)}): {exc}")
                continue
            pid = param_hash(scenario.to_dict())
            if pid in seen:
                raise SweepError(f"[sweep] points {seen[pid]} and {i} are the same scenario "
                                 f"({_label(values)}); remove the duplicate axis values")
            seen[pid] = i
            points.append(Point(index=i, values=values, scenario=scenario, id=pid))
        if bad:
            more = f" (and {len(bad) - _MAX_REPORTED} more)" if len(bad) > _MAX_REPORTED else ""
            raise SweepError(f"{len(bad)} of {self.n_points} sweep points are invalid "
                             f"scenarios{more}:\n  " + "\n  ".join(bad[:_MAX_REPORTED]))
        self._points.extend(points)
        return self._points


def _product(lists: list[tuple]) -> list[tuple]:
    out: list[tuple] = [()]
    for values in lists:
        out = [prev + (v,) for prev in out for v in values]
    return out


def _label(values: dict) -> str:
    return ", ".join(f"{k}={v!r}" for k, v in values.items())


def set_path(table: dict, path: str, value: Any) -> None:
    """Set ``value`` at the dotted ``path`` of a nested scenario table, in place.

    Dict levels that are missing are created (``parse_scenario`` then rejects unknown
    keys); list levels are addressed by a 0-based index that must exist.

    Raises
    ------
    SweepError
        If the path is malformed or runs through a missing list entry or a scalar.
    """
    keys = path.split(".")
    if not path or any(not k for k in keys):
        raise SweepError(f"[sweep.axes] path {path!r} is malformed (empty component)")
    node: Any = table
    for depth, key in enumerate(keys):
        where = ".".join(keys[:depth]) or "the scenario"
        last = depth == len(keys) - 1
        if isinstance(node, list):
            if not key.isdigit():
                raise SweepError(f"[sweep.axes] path {path!r}: {where} is a list; "
                                 f"expected a 0-based index, got {key!r}")
            idx = int(key)
            if idx >= len(node):
                raise SweepError(f"[sweep.axes] path {path!r}: index {idx} out of range, "
                                 f"{where} has {len(node)} entries in [base]")
            if last:
                node[idx] = value
            else:
                node = node[idx]
        elif isinstance(node, dict):
            if last:
                node[key] = value
            elif key in node:
                node = node[key]
            elif keys[depth + 1].isdigit():
                raise SweepError(f"[sweep.axes] path {path!r}: {where}.{key} does not "
                                 "exist in [base], so it cannot be indexed")
            else:
                node[key] = {}
                node = node[key]
        else:
            raise SweepError(f"[sweep.axes] path {path!r}: {where} is a value "
                             f"({node!r}), not a table or list")


# -- parsing ----------------------------------------------------------------------
_TOP_KEYS = {"name", "description", "base", "sweep", "ensemble"}
_ENSEMBLE_KEYS = {"seeds", "path", "first_seed", "batch"}
_SWEEP_KEYS = {"mode", "axes"}
_AXIS_KEYS = {"path", "name", "values", "linspace", "logspace", "integer", "with"}


def _check_keys(table: dict, allowed: set[str], where: str) -> None:
    unknown = set(table) - allowed
    if unknown:
        raise SweepError(f"unknown key(s) {sorted(unknown)} in [{where}]; "
                         f"allowed: {sorted(allowed)}")


def _range(raw: Any, kind: str, where: str) -> list[float]:
    if (not isinstance(raw, list) or len(raw) != 3
            or any(isinstance(x, bool) or not isinstance(x, int | float) for x in raw)):
        raise SweepError(f"[{where}] {kind} must be [lo, hi, n] (numbers), got {raw!r}")
    lo, hi, n = raw
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise SweepError(f"[{where}] {kind} bounds must be finite, got {raw!r}")
    if not isinstance(n, int) or n < 1:
        raise SweepError(f"[{where}] {kind} count n must be an integer >= 1, got {n!r}")
    if n > MAX_POINTS:  # checked before np.linspace allocates n values
        raise SweepError(f"[{where}] {kind} count n = {n} is beyond any sweep; allowed "
                         f"range [1, {MAX_POINTS}] (MAX_POINTS)")
    if n == 1 and lo != hi:
        raise SweepError(f"[{where}] {kind} with n = 1 needs lo == hi, got {raw!r}")
    if kind == "logspace":
        if lo <= 0 or hi <= 0:
            raise SweepError(f"[{where}] logspace bounds must be > 0 (they are values, "
                             f"not exponents), got {raw!r}")
        vals = np.geomspace(lo, hi, n)
    else:
        vals = np.linspace(lo, hi, n)
    vals[0], vals[-1] = lo, hi  # exact end points
    return [float(v) for v in vals]


def _parse_axis(raw: Any, i: int) -> Axis:
    where = f"sweep.axes[{i}]"
    if not isinstance(raw, dict):
        raise SweepError(f"[{where}] must be a table ([[sweep.axes]]), got {raw!r}")
    _check_keys(raw, _AXIS_KEYS, where)
    path = raw.get("path")
    if not isinstance(path, str) or not path:
        raise SweepError(f"[{where}] path is required: a dotted path such as "
                         "'chain.sections.1.alpha_rho'")
    where = f"sweep.axes[{i}] ({path})"
    sources = [k for k in ("values", "linspace", "logspace") if k in raw]
    if len(sources) != 1:
        raise SweepError(f"[{where}] give exactly one of values, linspace, logspace "
                         f"(got {sources or 'none'})")
    src = sources[0]
    if src == "values":
        values = raw["values"]
        if not isinstance(values, list):
            raise SweepError(f"[{where}] values must be a list, got {values!r}")
        for v in values:
            if isinstance(v, list | dict) or (isinstance(v, float) and not math.isfinite(v)):
                raise SweepError(f"[{where}] values must be finite numbers, strings or "
                                 f"booleans, got {v!r}")
    else:
        values = _range(raw[src], src, where)
    integer = raw.get("integer", False)
    if not isinstance(integer, bool):
        raise SweepError(f"[{where}] integer must be true or false, got {integer!r}")
    if integer:
        if any(isinstance(v, bool) or not isinstance(v, int | float) for v in values):
            raise SweepError(f"[{where}] integer = true needs numeric values")
        values = [int(round(v)) for v in values]
    if not values:
        raise SweepError(f"[{where}] the axis is empty: give at least one value")
    name = raw.get("name", path)
    if not isinstance(name, str) or not name or "/" in name:
        raise SweepError(f"[{where}] name must be a non-empty string without '/', "
                         f"got {name!r}")
    if name in RESERVED_COLUMNS:
        raise SweepError(f"[{where}] name {name!r} is a reserved column of the results "
                         f"table; reserved: {sorted(RESERVED_COLUMNS)}")
    follows = raw.get("with", "")
    if not isinstance(follows, str) or "with" in raw and not follows:
        raise SweepError(f"[{where}] with must name an earlier axis, got {follows!r}")
    return Axis(path=path, name=name, values=tuple(values), follows=follows)


def parse_sweep_spec(data: dict, *, default_name: str = "sweep",
                     validate_points: bool = True) -> SweepSpec:
    """Validate a sweep specification given as nested dicts (the parsed TOML).

    Parameters
    ----------
    data : dict
        Tables ``base`` and ``sweep`` (and optional ``name``, ``description``).
    default_name : str
        Name used when ``data`` has none (a file's stem).
    validate_points : bool
        Also expand and validate every point (default); see :meth:`SweepSpec.points`.

    Returns
    -------
    SweepSpec

    Raises
    ------
    SweepError
        On unknown keys, bad paths, empty axes or any invalid point.
    """
    if not isinstance(data, dict):
        raise SweepError("a sweep specification must be a table")
    _check_keys(data, _TOP_KEYS, "top level")
    name = data.get("name", default_name)
    description = data.get("description", "")
    if not isinstance(name, str) or not name:
        raise SweepError(f"name must be a non-empty string, got {name!r}")
    if not isinstance(description, str):
        raise SweepError(f"description must be a string, got {description!r}")
    base = data.get("base")
    if not isinstance(base, dict):
        raise SweepError("[base] is required: a scenario table (the schema of scenario "
                         "files) that the sweep varies")
    try:
        parse_scenario(base)
    except ScenarioError as exc:
        raise SweepError(f"[base] is not a valid scenario: {exc}") from None
    sweep = data.get("sweep")
    if not isinstance(sweep, dict):
        raise SweepError("[sweep] is required, with one or more [[sweep.axes]]")
    _check_keys(sweep, _SWEEP_KEYS, "sweep")
    mode = sweep.get("mode", "product")
    if mode not in ("product", "zip"):
        raise SweepError(f"[sweep] mode = {mode!r}; allowed: ['product', 'zip']")
    ensemble = _parse_ensemble(data["ensemble"], base) if "ensemble" in data else None
    raw_axes = sweep.get("axes", [] if ensemble is not None else None)
    if not isinstance(raw_axes, list) or not (raw_axes or ensemble is not None):
        raise SweepError("[sweep] axes is required: one or more [[sweep.axes]] tables")
    axes = tuple(_parse_axis(a, i) for i, a in enumerate(raw_axes))
    if ensemble is not None:
        if mode != "product":
            raise SweepError("[ensemble] needs [sweep] mode = 'product' (the seed axis "
                             "multiplies the points of the other axes)")
        if any(a.name == ensemble.name for a in axes):
            raise SweepError(f"[sweep.axes] the name {ensemble.name!r} is the [ensemble]'s "
                             "seed axis; rename the axis")
        axes += (ensemble.axis(),)
    _check_axes(axes, mode)
    total = math.prod(len(a.values) for a in axes if not a.follows) \
        if mode == "product" else len(axes[0].values)
    if total > MAX_POINTS:  # before any point (or its scenario) is built
        raise SweepError(f"[sweep.axes] the sweep has {total} points "
                         f"({' x '.join(str(len(a.values)) for a in axes)}, {mode}); "
                         f"allowed at most {MAX_POINTS} (MAX_POINTS): split it or "
                         "coarsen an axis")
    for axis in axes:  # a bad path is reported once, not once per point
        set_path(copy.deepcopy(base), axis.path, axis.values[0])
    spec = SweepSpec(name=name, base=base, axes=axes, mode=mode, description=description,
                     ensemble=ensemble)
    if validate_points:
        spec.points()
    return spec


def _parse_ensemble(raw: Any, base: dict) -> EnsembleSpec:
    """The ``[ensemble]`` table (module docstring)."""
    if not isinstance(raw, dict):
        raise SweepError(f"[ensemble] must be a table, got {raw!r}")
    _check_keys(raw, _ENSEMBLE_KEYS, "ensemble")
    vals = {}
    for key, low, default in (("seeds", 1, None), ("first_seed", 0, 0), ("batch", 1, 64)):
        v = raw.get(key, default)
        if v is None:
            raise SweepError("[ensemble] seeds is required: the number of realisations "
                             "per point (an integer >= 1)")
        if isinstance(v, bool) or not isinstance(v, int) or not low <= v <= MAX_POINTS:
            raise SweepError(f"[ensemble] {key} must be an integer in [{low}, {MAX_POINTS}], "
                             f"got {v!r}")
        vals[key] = v
    path = raw.get("path")
    if path is None:
        sections = (base.get("chain") or {}).get("sections") or []
        disordered = [i for i, s in enumerate(sections) if isinstance(s, dict) and any(
            s.get(k) for k in ("disorder_mass", "disorder_stiffness", "disorder_diameter"))]
        if len(disordered) != 1:
            raise SweepError(f"[ensemble] path is required: [base] has {len(disordered)} "
                             "disordered sections (the default is the seed of the one "
                             "disordered section, e.g. 'chain.sections.0.seed')")
        path = f"chain.sections.{disordered[0]}.seed"
    if not isinstance(path, str) or not path:
        raise SweepError(f"[ensemble] path must be a dotted path such as "
                         f"'chain.sections.0.seed', got {path!r}")
    return EnsembleSpec(seeds=vals["seeds"], path=path, first_seed=vals["first_seed"],
                        batch=vals["batch"])


def _check_axes(axes: tuple[Axis, ...], mode: str) -> None:
    paths = [a.path for a in axes]
    names = [a.name for a in axes]
    for i, p in enumerate(paths):
        for q in paths[i + 1:]:
            if p == q or q.startswith(p + ".") or p.startswith(q + "."):
                raise SweepError(f"[sweep.axes] paths {p!r} and {q!r} overlap")
    if len(set(names)) != len(names):
        raise SweepError(f"[sweep.axes] column names must be unique, got {names}")
    for i, axis in enumerate(axes):
        if not axis.follows:
            continue
        where = f"[sweep.axes[{i}]] ({axis.path}) with = {axis.follows!r}"
        if mode == "zip":
            raise SweepError(f"{where}: in mode = 'zip' every axis already goes with the "
                             "others; remove 'with'")
        lead = {a.name: a for a in axes[:i] if not a.follows}
        if axis.follows not in lead:
            raise SweepError(f"{where} must name an earlier axis that is not itself "
                             f"linked; allowed: {sorted(lead)}")
        if len(axis.values) != len(lead[axis.follows].values):
            raise SweepError(f"{where}: {len(axis.values)} values, but that axis has "
                             f"{len(lead[axis.follows].values)}; give one per value")
    for axis in axes if mode == "product" else ():
        if axis.follows:
            continue
        # one dimension: the axis with its linked axes (each may repeat a value)
        linked = [a for a in axes if a is axis or a.follows == axis.name]
        reprs = [canonical_json([a.values[j] for a in linked] if len(linked) > 1
                                else axis.values[j]) for j in range(len(axis.values))]
        if len(set(reprs)) != len(reprs):
            dup = sorted({r for r in reprs if reprs.count(r) > 1})
            raise SweepError(f"[sweep.axes] ({axis.path}) duplicate values {dup} "
                             "(after rounding, for integer axes)")
    if mode == "zip":
        lengths = {a.path: len(a.values) for a in axes}
        if len(set(lengths.values())) != 1:
            raise SweepError(f"[sweep] mode = 'zip' needs axes of equal length, got {lengths}")


def shipped_sweeps() -> dict[str, Path]:
    """The example sweeps shipped in ``hertzchain/sweeps`` by name (file stem)."""
    from importlib.resources import files

    folder = files("hertzchain") / "sweeps"
    return {Path(f.name).stem: Path(str(f)) for f in folder.iterdir()
            if f.name.endswith(".toml")}


def load_sweep_spec(path: str | Path, *, validate_points: bool = True) -> SweepSpec:
    """Read and validate a sweep TOML file (see the module docstring for the format).

    A path that does not exist but names a shipped sweep (``"fig7_map"`` or
    ``"fig7_map.toml"``, see :func:`shipped_sweeps`) loads that one.
    """
    path = Path(path)
    if not path.exists() and path.parent == Path("."):
        shipped = shipped_sweeps()
        name = path.stem if path.suffix == ".toml" else path.name
        if name in shipped:
            path = shipped[name]
        elif not path.suffix:
            raise SweepError(f"sweep file not found: {path} (shipped sweeps: "
                             f"{sorted(shipped)})")
    data = read_toml(path, SweepError, "sweep file")
    try:
        return parse_sweep_spec(data, default_name=path.stem,
                                validate_points=validate_points)
    except ScenarioError as exc:
        raise SweepError(f"{path}: {exc}") from None
