"""Storage of sweep results: an append-only record log and the consolidated HDF5 table.

Layout of a sweep's output directory::

    DIR/records.jsonl   one JSON line per finished point, appended and fsync'ed as each
                        result arrives (the crash-safe source of truth; a torn last line
                        from a crash is skipped; the latest record of an id wins); each
                        line ends with the SHA-256 of its own text
    DIR/results.h5      the consolidated table, rebuilt from the records and renamed
                        into place atomically (periodically and at the end); sealed
                        and verified on read (:mod:`theory.integrity`)
    DIR/spec.json       the sweep specification of the last run
    DIR/runs/<id>.h5    full per-run output (only with ``full_output``)

Why not append to the HDF5 file directly: an HDF5 file open for writing is not
crash-safe (a killed writer can leave it unreadable), whereas a line-oriented log loses
at most the line being written, and an atomic rename never exposes a partial table.

``results.h5`` holds one group ``/table`` with one 1-D dataset per column, one row per
point of the sweep in the sweep's order (see :func:`write_table` for the columns); the
file attributes carry the format name and version and the counts of ok, unverified,
failed and pending points, and the scalar string dataset ``/spec_json`` the sweep specification.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from theory import integrity

from .. import __version__
from .spec import Point, SweepSpec

_DAMAGED_ADVICE = ("Delete that line (its point is then computed again) or move the "
                   "directory aside to start the sweep over")

__all__ = [
    "records_from_table",
    "FORMAT",
    "FORMAT_VERSION",
    "SUMMARY_FIELDS",
    "RecordStore",
    "SweepResults",
    "derived_columns",
    "write_table",
    "read_results",
]

FORMAT = "hertzchain-sweep-results"
FORMAT_VERSION = 1

SUMMARY_FIELDS = (
    "Ek_tr", "Ek_re", "Ep_tr", "Ep_re", "Et_tr", "Et_re",
    "front_speed_tr", "front_speed_re", "front_speed_tr_over_c0L",
    "transmitted", "reflected", "n_transmitted_pulses", "energy_drift",
    "steps", "dt", "wall_time", "stopped_by", "completed",
)
"""Keys every run summary must have (the runner's contract); extra scalar keys are kept.

``completed`` (bool) says whether the run reached the stop its scenario asked for and
``stopped_by`` what ended it (:func:`hertzchain.runner.run_outcome`); the labels
``transmitted``/``reflected`` may be None (stored as "") where they are undefined."""

UNITS = {
    "front_speed_tr": "m/s", "front_speed_re": "m/s", "dt": "s", "wall_time": "s",
    "point_wall_time": "s",
}
INT_FILL = -1
"""Fill value of integer (and boolean, stored as int8) columns for points without it."""


class RecordStore:
    """Append-only JSON-lines log of finished points (crash-safe).

    Parameters
    ----------
    path : path-like
        The ``records.jsonl`` file (created on the first append).
    """

    def __init__(self, path: str | os.PathLike):
        self.path = Path(path)

    def load(self) -> dict[str, dict]:
        """All records by point id; later lines supersede earlier ones.

        Every line carries the SHA-256 of its own text
        (:func:`theory.integrity.dumps_sealed_json`).  A last line without its newline
        was torn by a crash while being appended and is skipped (:meth:`append_many`
        cuts it off); any other line that fails its digest is damage.

        Raises
        ------
        theory.integrity.IntegrityError
            (a ``ValueError``) naming the file and the line of a damaged record.
        """
        records: dict[str, dict] = {}
        if not self.path.exists():
            return records
        lines = self.path.read_bytes().split(b"\n")
        last = lines.pop()  # "" after a final newline, else a line torn by a crash ...
        if last:  # ... unless it is a whole record whose newline was damaged
            try:
                integrity.loads_sealed_json(last[:-1].decode("utf-8"), where="")
            except ValueError:  # (UnicodeDecodeError included) torn: skipped, point reruns
                pass
            else:
                raise integrity.IntegrityError(
                    f"{self.path} line {len(lines) + 1}: damaged (its final newline "
                    f"changed). {_DAMAGED_ADVICE}")
        for number, raw in enumerate(lines, start=1):
            where = f"{self.path} line {number}"
            try:
                text = raw.decode("utf-8")
            except UnicodeDecodeError:
                raise integrity.IntegrityError(
                    f"{where}: damaged (not UTF-8 text). {_DAMAGED_ADVICE}") from None
            try:
                rec = integrity.loads_sealed_json(text, where=where)
            except integrity.IntegrityError as exc:
                raise integrity.IntegrityError(f"{exc}. {_DAMAGED_ADVICE}") from None
            if not isinstance(rec.get("id"), str):
                raise integrity.IntegrityError(f"{where}: not a sweep record (no id)")
            records[rec["id"]] = rec
        return records

    def append(self, record: Mapping) -> dict:
        """Append one record, flush and fsync; return it as it reads back from disk."""
        return self.append_many([record])[0]

    def append_many(self, records: Sequence[Mapping]) -> list[dict]:
        """Append records with one write and one fsync; return them as read back."""
        lines = [integrity.dumps_sealed_json(r, default=_json_default) for r in records]
        if not lines:
            return []
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with self.path.open("a+b") as fh:
            end = fh.seek(0, os.SEEK_END)
            if end > 0:  # cut off a line torn by an earlier crash (its point reruns)
                fh.seek(end - 1)
                if fh.read(1) != b"\n":
                    fh.truncate(_after_last_newline(fh, end))
            fh.write("".join(line + "\n" for line in lines).encode("utf-8"))
            fh.flush()
            os.fsync(fh.fileno())
        return [integrity.loads_sealed_json(line, where=str(self.path)) for line in lines]


def _after_last_newline(fh, end: int) -> int:
    """Offset just after the last newline before ``end`` in ``fh`` (0 if there is none)."""
    pos = end
    while pos > 0:
        start = max(0, pos - 65536)
        fh.seek(start)
        i = fh.read(pos - start).rfind(b"\n")
        if i >= 0:
            return start + i + 1
        pos = start
    return 0


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    return str(obj)


# -- columns ------------------------------------------------------------------------
def derived_columns(point: Point) -> dict[str, Any]:
    """Interface ratios of the first interface and their theory predictions.

    ``alpha_rho``, ``alpha_kn`` are section 1 relative to section 0 (NaN if the chain has
    one section or its first two sections are given by materials), ``gamma_c0``,
    ``gamma_RG`` (Eqs. 9, 13) and ``theory_region`` (Fig. 7 region, "" if undefined).
    """
    import theory

    chain = point.scenario.chain
    out: dict[str, Any] = {"alpha_rho": math.nan, "alpha_kn": math.nan,
                           "delta0_over_d": chain.delta0_over_d, "gamma_c0": math.nan,
                           "gamma_RG": math.nan, "theory_region": ""}
    s = chain.sections
    if len(s) >= 2 and s[0].material is None and s[1].material is None:
        ar, ak = s[1].alpha_rho / s[0].alpha_rho, s[1].alpha_kn / s[0].alpha_kn
        gc, gr = float(theory.gamma_c0(ar, ak)), float(theory.gamma_rg(ar, ak))
        out.update(alpha_rho=ar, alpha_kn=ak, gamma_c0=gc, gamma_RG=gr,
                   theory_region=theory.region(gc, gr))
    return out


def _column(values: Sequence[Any]) -> tuple[np.ndarray, dict]:
    """Typed array for one column; ``None`` marks a missing entry.

    A column whose entries are lists of numbers of one length (a profile per point,
    e.g. an ensemble realisation's ``amplitude_profile``) is a 2-D float array, NaN
    rows where missing.
    """
    present = [v for v in values if v is not None]
    if present and all(isinstance(v, list) and v and all(
            isinstance(x, int | float) and not isinstance(x, bool) for x in v)
            for v in present) and len({len(v) for v in present}) == 1:
        width = len(present[0])
        return np.array([[math.nan] * width if v is None else [float(x) for x in v]
                         for v in values], dtype=float).reshape(len(values), width), {}
    if present and all(isinstance(v, bool) for v in present):
        arr = np.array([INT_FILL if v is None else int(v) for v in values], dtype=np.int8)
        return arr, {"fill_value": INT_FILL, "boolean": True}
    if present and all(isinstance(v, int) and not isinstance(v, bool) for v in present):
        return np.array([INT_FILL if v is None else v for v in values], dtype=np.int64), \
            {"fill_value": INT_FILL}
    if present and all(isinstance(v, int | float) and not isinstance(v, bool)
                       for v in present):
        return np.array([math.nan if v is None else float(v) for v in values]), {}
    text = [("" if v is None else v if isinstance(v, str)
             else json.dumps(v, sort_keys=True, default=_json_default)) for v in values]
    return np.array(text, dtype=object), {}


def _summary_keys(records: Iterable[dict]) -> list[str]:
    extra: set[str] = set()
    for rec in records:
        extra.update(rec.get("summary") or {})
    return list(SUMMARY_FIELDS) + sorted(extra - set(SUMMARY_FIELDS))


def build_columns(points: Sequence[Point], records: Mapping[str, dict]
                  ) -> tuple[dict[str, np.ndarray], dict[str, dict]]:
    """Columns (name -> array) and their attributes for the given points and records."""
    recs = [records.get(p.id) for p in points]
    cols: dict[str, list] = {"id": [p.id for p in points], "index": [p.index for p in points]}
    kinds = {"id": "meta", "index": "meta"}
    for name in (points[0].values if points else {}):
        cols[name] = [p.values[name] for p in points]
        kinds[name] = "parameter"
    derived = [derived_columns(p) for p in points]
    for name in (derived[0] if derived else {}):
        cols[name] = [d[name] for d in derived]
        kinds[name] = "derived"
    cols["status"] = [r["status"] if r else "pending" for r in recs]
    cols["error"] = [r.get("error", "") if r else "" for r in recs]
    cols["point_wall_time"] = [r.get("point_wall_time") if r else None for r in recs]
    cols["worker"] = [r.get("worker", "") if r else "" for r in recs]
    cols["full_output"] = [r.get("full_output", "") if r else "" for r in recs]
    cols["point_function"] = [r.get("point_function", "") if r else "" for r in recs]
    for name in ("status", "error", "point_wall_time", "worker", "full_output",
                 "point_function"):
        kinds[name] = "meta"
    for key in _summary_keys(r for r in recs if r):
        col = key if key not in cols else f"summary.{key}"
        cols[col] = [(r.get("summary") or {}).get(key) if r else None for r in recs]
        kinds[col] = "summary"
    arrays, attrs = {}, {}
    for name, values in cols.items():
        arr, extra = _column(values)
        if name in ("status", "error", "worker", "full_output", "point_function", "id",
                    "theory_region"):
            arr = np.array(["" if v is None else str(v) for v in values], dtype=object)
            extra = {}
        arrays[name] = arr
        attrs[name] = {"kind": kinds[name], **extra}
        if name in UNITS:
            attrs[name]["unit"] = UNITS[name]
    return arrays, attrs


def write_table(path: str | os.PathLike, spec: SweepSpec, points: Sequence[Point],
                records: Mapping[str, dict], *, complete: bool | None = None) -> Path:
    """Atomically (re)write the consolidated results table.

    Parameters
    ----------
    path : path-like
        Target ``results.h5``.
    spec : SweepSpec
        The sweep (stored as the ``/spec_json`` dataset; axis paths on the columns).
    points : sequence of Point
        Rows, in order.
    records : mapping
        Finished records by point id (points without one are ``"pending"``).
    complete : bool, optional
        Stored as an attribute; default: no point is pending.

    Returns
    -------
    pathlib.Path
        ``path``.

    Notes
    -----
    Columns of ``/table``: ``id`` (12-hex param_hash of the point's scenario), ``index``
    (position in the sweep), one column per axis (its ``name``; attribute ``path``), the
    derived interface columns of :func:`derived_columns`, ``status`` ("ok", "unverified"
    — ran, but not verified to its rtol, docs/guide/exit_status.md —, "failed" or
    "pending"), ``error``, ``point_wall_time`` (s, measured around the point function),
    ``worker``, ``full_output`` (path of the per-run file or ""), ``point_function``
    (``module:name`` of the function that made the record), then the run summary's
    keys (:data:`SUMMARY_FIELDS` first, extra keys sorted).  Missing numbers are NaN,
    missing integers -1 (attribute ``fill_value``), missing strings "".
    """
    path = Path(path)
    arrays, attrs = build_columns(points, records)
    status = arrays["status"]
    counts = {s: int(np.count_nonzero(status == s))
              for s in ("ok", "unverified", "failed", "pending")}
    axis_paths = {a.name: a.path for a in spec.axes}
    with integrity.sealed_hdf5(path, in_memory=True) as fh:  # a full disk: clean OSError
        fh.attrs["format"] = FORMAT
        fh.attrs["format_version"] = FORMAT_VERSION
        fh.attrs["hertzchain_version"] = __version__
        # a dataset, not an attribute: a long list of zipped values can exceed the
        # 64 kB limit of an HDF5 attribute
        fh.create_dataset("spec_json", data=spec.to_json(), dtype=h5py.string_dtype("utf-8"))
        fh.attrs["name"] = spec.name
        fh.attrs["n_points"] = len(points)
        for key, n in counts.items():
            fh.attrs[f"n_{key}"] = n
        fh.attrs["complete"] = bool(counts["pending"] == 0 if complete is None else complete)
        fh.attrs["updated"] = datetime.now(UTC).isoformat(timespec="seconds")
        grp = fh.create_group("table")
        grp.attrs["columns"] = list(arrays)
        grp.attrs["axes"] = [a.name for a in spec.axes]
        for name, arr in arrays.items():
            if arr.dtype == object:
                ds = grp.create_dataset(name, data=arr.astype(str).tolist() if arr.size else [],
                                        dtype=h5py.string_dtype("utf-8"))
            else:
                ds = grp.create_dataset(name, data=arr)
            for key, val in attrs[name].items():
                ds.attrs[key] = val
            if name in axis_paths:
                ds.attrs["path"] = axis_paths[name]
        if getattr(spec, "ensemble", None) is not None:
            _write_ensemble(fh, spec, points, records)
    return path


def _write_ensemble(fh, spec: SweepSpec, points: Sequence[Point],
                    records: Mapping[str, dict]) -> None:
    """The ``/ensemble`` table: statistics over each point's finished realisations.

    One row per point of the other axes (:func:`hertzchain.sweep.ensemble.ensemble_table`);
    the attribute ``profile_grains`` gives the grains of the 2-D profile columns.
    """
    from .ensemble import ensemble_table, profile_grains

    name = spec.ensemble.name
    groups: dict[str, tuple[dict, list]] = {}
    n_grains = None
    for p in points:
        values = {k: v for k, v in p.values.items() if k != name}
        key = json.dumps(values, sort_keys=True, default=_json_default)
        rec = records.get(p.id)
        entry = groups.setdefault(key, (values, []))
        if rec is not None and rec.get("status") == "ok":
            entry[1].append(rec.get("summary") or {})
            n_grains = n_grains or (rec.get("summary") or {}).get("n_grains")
    table = ensemble_table([g[0] for g in groups.values()], [g[1] for g in groups.values()])
    grp = fh.create_group("ensemble")
    grp.attrs["columns"] = list(table)
    grp.attrs["profile_grains"] = (profile_grains(int(n_grains)) if n_grains
                                   else np.zeros(0, np.int64))
    for col, arr in table.items():
        if arr.dtype == object:
            grp.create_dataset(col, data=[str(x) for x in arr],
                               dtype=h5py.string_dtype("utf-8"))
        else:
            grp.create_dataset(col, data=arr)


@dataclass
class SweepResults:
    """A results table read back from ``results.h5``.

    Attributes
    ----------
    columns : dict of str to numpy.ndarray
        Column arrays in table order; string columns are object arrays of ``str``.
    kinds : dict of str to str
        ``"meta"``, ``"parameter"``, ``"derived"`` or ``"summary"`` per column.
    attrs : dict
        File attributes (format, counts...) and ``spec_json`` (the sweep, JSON text).
    axes : list of str
        Names of the swept columns.
    """

    columns: dict[str, np.ndarray]
    kinds: dict[str, str] = field(default_factory=dict)
    attrs: dict = field(default_factory=dict)
    axes: list[str] = field(default_factory=list)
    path: Path | None = None
    ensemble: dict[str, np.ndarray] = field(default_factory=dict)
    """The ``/ensemble`` statistics table of an ensemble sweep (column -> array; the
    grains of its profile columns under ``"profile_grains"``); empty otherwise."""

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    def __contains__(self, name: str) -> bool:
        return name in self.columns

    def __len__(self) -> int:
        return len(self.columns["id"])

    @property
    def ok(self) -> np.ndarray:
        """Boolean mask of points whose status is ``"ok"``."""
        return self.columns["status"] == "ok"

    @property
    def spec(self) -> dict:
        """The sweep specification as a dict."""
        return json.loads(self.attrs.get("spec_json", "{}"))

    def row(self, i: int) -> dict[str, Any]:
        """One row as a dict of Python scalars."""
        return {k: (v[i].item() if isinstance(v[i], np.generic) else v[i])
                for k, v in self.columns.items()}

    def to_pandas(self):
        """The table as a :class:`pandas.DataFrame` (needs pandas)."""
        import pandas as pd

        return pd.DataFrame(self.columns)


def read_results(path: str | os.PathLike) -> SweepResults:
    """Read ``results.h5`` (or the sweep directory that contains it)."""
    path = Path(path)
    if path.is_dir():
        path = path / "results.h5"
    if not path.exists():
        raise FileNotFoundError(f"no sweep results table at {path}")
    try:
        return _read_results(path)
    except (OSError, KeyError) as exc:
        raise ValueError(f"{path}: not a readable sweep results table (truncated or "
                         f"corrupted?): {exc}") from None


def _read_results(path: Path) -> SweepResults:
    with integrity.open_hdf5(path, what="sweep results table") as fh:
        if fh.attrs.get("format") != FORMAT:
            raise ValueError(f"{path} is not a hertzchain sweep results table "
                             f"(format attribute {fh.attrs.get('format')!r})")
        attrs = {k: (v.item() if isinstance(v, np.generic) else v) for k, v in fh.attrs.items()}
        if "spec_json" in fh:
            attrs["spec_json"] = fh["spec_json"].asstr()[()]
        grp = fh["table"]
        names = [str(n) for n in grp.attrs["columns"]]
        columns, kinds = {}, {}
        for name in names:
            ds = grp[name]
            if h5py.check_string_dtype(ds.dtype) is not None:
                columns[name] = np.array(ds.asstr()[()], dtype=object).reshape(-1)
            else:
                columns[name] = ds[()]
            kinds[name] = str(ds.attrs.get("kind", ""))
        axes = [str(n) for n in grp.attrs.get("axes", [])]
        ensemble: dict[str, np.ndarray] = {}
        if "ensemble" in fh:
            eg = fh["ensemble"]
            for name in [str(n) for n in eg.attrs["columns"]]:
                ds = eg[name]
                ensemble[name] = (np.array(ds.asstr()[()], dtype=object).reshape(-1)
                                  if h5py.check_string_dtype(ds.dtype) is not None
                                  else ds[()])
            ensemble["profile_grains"] = np.asarray(eg.attrs["profile_grains"])
    return SweepResults(columns=columns, kinds=kinds, attrs=attrs, axes=axes, path=path,
                        ensemble=ensemble)


def records_from_table(path: str | os.PathLike) -> dict[str, dict]:
    """The finished points' records rebuilt from a ``results.h5`` (by point id).

    For a sweep directory whose ``records.jsonl`` is lost: the table holds every
    finished point's status, error, bookkeeping and summary, so it is the source the
    records are restored from (instead of being overwritten by an all-pending table).
    Integer and boolean columns come back as ``int``/``bool`` (their fill value as
    None), numbers as ``float``, text as ``str``; the per-point ``traceback`` (not in the
    table) is lost.  The table is verified (:func:`theory.integrity.open_hdf5`).
    """
    path = Path(path)
    records: dict[str, dict] = {}
    with integrity.open_hdf5(path, what="sweep results table") as fh:
        grp = fh["table"]
        names = [str(n) for n in grp.attrs["columns"]]
        axes = [str(n) for n in grp.attrs.get("axes", [])]
        cols, info = {}, {}
        for name in names:
            ds = grp[name]
            if h5py.check_string_dtype(ds.dtype) is not None:
                cols[name] = [str(x) for x in ds.asstr()[()]]
            else:
                cols[name] = ds[()].tolist()
            info[name] = dict(ds.attrs)
    n = len(cols["id"])

    def value(name: str, i: int):
        v, a = cols[name][i], info[name]
        if "fill_value" in a and v == int(a["fill_value"]):
            return None
        return bool(v) if a.get("boolean") else v

    for i in range(n):
        status = cols["status"][i]
        if status not in ("ok", "unverified", "failed"):
            continue
        rec = {"id": cols["id"][i], "values": {a: cols[a][i] for a in axes},
               "status": status, "error": cols["error"][i],
               "point_wall_time": value("point_wall_time", i),
               "worker": cols["worker"][i], "full_output": cols["full_output"][i],
               "point_function": cols["point_function"][i],
               "restored_from": str(path), "summary": {}}
        if status in ("ok", "unverified"):
            for name in names:
                if str(info[name].get("kind", "")) == "summary":
                    key = name.removeprefix("summary.")
                    rec["summary"][key] = value(name, i)
        records[rec["id"]] = rec
    return records
