"""HDF5 output of a :class:`~discrete.simulation.Simulation` (h5py).

Layout: root attributes ``format``, ``package_version``, ``solver``, ``dt`` (s),
``steps``, ``t`` (s), ``t0`` (s), ``energy0`` (J), ``energy_drift``, ``wall_left``,
``wall_right`` (m), ``chain_params``, ``recording`` and ``contact_law`` (JSON,
:meth:`theory.laws.ContactLaw.to_dict`; absent means Hertz), ``drag`` (1/s) and
``units`` (JSON: the unit of every dataset); groups ``chain`` (mass, k, delta0,
diameter, section), ``state`` (u, v, a; optional ``dissipated``, the energy booked per
contact, and ``delta_expected``, the largest expected overlaps of the run's initial
state, with the attribute ``dt_default``), ``record`` (series, energy grid, monitor,
maxima), ``snapshots/<i>`` (u, v, overlaps with attributes label, t, step) and,
optionally, ``train``: the solitary waves of the final state
(:class:`discrete.waves.Train`; one dataset per field of
:data:`discrete.waves.TRAIN_FIELDS`, each with its ``units``, and the split's
parameters ``t`` (s), ``threshold``, ``valley``, ``lo``, ``hi`` and ``count`` as
attributes; read with :func:`load_train`).  What is
written is what :meth:`discrete.Simulation.saved` returns, and :func:`load` hands it to
:meth:`discrete.Simulation.restore`: this module only maps it to and from HDF5.
Datasets of 64 or more entries are chunked and gzip-compressed.  Optional root
attributes: ``integrator`` (the time stepper's name, :mod:`discrete.integrators`; absent
means ``"verlet"``) and whatever the caller passes as ``attrs`` (the runner adds the
scenario and the summary, a checkpoint its key).

Integrity (:mod:`theory.integrity`): the file is written through
:func:`theory.integrity.sealed_hdf5` — to a hidden temporary file in the target
directory, sealed with the SHA-256 digest of every byte, flushed to disk and renamed
when complete — and :func:`load` verifies the seal before reading anything, so a
change of any attribute, dataset or byte since the file was written is an error, never
a silently different run.  The seal is a file-level wrapper around what is written.
:func:`load` turns every way a file can be unreadable — missing, not sealed, changed,
not HDF5, a dataset or attribute missing, inconsistent shapes — into one
:class:`ValueError` that names the file and what is wrong, instead of an h5py
traceback.
"""

from __future__ import annotations

import importlib.metadata
import json
import os
from fractions import Fraction
from pathlib import Path

import h5py
import numpy as np

from theory import integrity
from theory.laws import HERTZ, law_from_dict

from .chain import Chain
from .integrators import get_integrator
from .recording import Record, Recording, Snapshot, event_from_dict, event_to_dict
from .simulation import SavedSimulation, Simulation
from .waves import TRAIN_FIELDS, Train

__all__ = ["save", "load", "load_train", "to_xarray", "UNITS", "FORMAT",
           "contact_constant_unit", "units_for"]

FORMAT = "hertzchain.discrete/1"
UNITS = {
    "t": "s", "dt": "s", "t0": "s", "energy0": "J", "wall_left": "m", "wall_right": "m",
    "mass": "kg", "k": "N/m^(3/2)", "delta0": "m", "diameter": "m", "section": "1",
    "u": "m", "v": "m/s", "a": "m/s^2", "overlaps": "m", "series": "m, m/s, m, m",
    "series_t": "s", "energy_t": "s", "energy_kinetic": "J", "energy_potential": "J",
    "monitor_t": "s", "monitor_energy": "J", "monitor_shadow": "J", "monitor_dissipated": "J",
    "vmax": "m/s", "umax": "m", "dissipated": "J", "delta_expected": "m", "drag": "1/s",
    "sensor_grains": "1", "sensor_force": "N", "wall_force": "N", "overlap_max": "m",
    "vmax_refined": "m/s", "vmax_time": "s", "peak_state": "mixed (discrete.kernels)",
    "dt_default": "s", "dissipation_rate0": "W",
}
"""The unit of every dataset of a Hertz run; :func:`units_for` those of any law."""


def contact_constant_unit(exponent: float) -> str:
    """Unit of the contact constant k of F = k δⁿ: N/m^n (``"N/m^(3/2)"`` for Hertz).

    F in N and δ in m make k a force per length to the n-th power; half-integer and
    other rational n are written as a fraction (n = 1: ``"N/m"``, 2: ``"N/m^2"``,
    5/2: ``"N/m^(5/2)"``).
    """
    q = Fraction(float(exponent)).limit_denominator(1000)
    if q == 1:
        return "N/m"
    if q.denominator == 1:
        return f"N/m^{q.numerator}"
    if float(q) == float(exponent):
        return f"N/m^({q.numerator}/{q.denominator})"
    return f"N/m^{float(exponent):g}"


def units_for(law) -> dict[str, str]:
    """:data:`UNITS` with the contact constant's unit for ``law``'s exponent."""
    return {**UNITS, "k": contact_constant_unit(law.exponent)}


def _version() -> str:
    try:
        return importlib.metadata.version("hertzchain")
    except importlib.metadata.PackageNotFoundError:  # pragma: no cover
        return "unknown"


def _ds(group: h5py.Group, name: str, data, compress: bool = True,
        units: dict | None = None) -> None:
    data = np.asarray(data)
    if data.size >= 64:
        kw = {"compression": "gzip", "compression_opts": 4, "shuffle": True} if compress \
            else {}
        group.create_dataset(name, data=data, chunks=True, **kw)
    else:
        group.create_dataset(name, data=data)
    units = UNITS if units is None else units
    if name in units:
        group[name].attrs["units"] = units[name]


def save(path: str | os.PathLike, sim: Simulation, *, attrs: dict | None = None,
         compress: bool = True, train: Train | None = None) -> Path:
    """Write ``sim`` (chain, state, recording, record) to the HDF5 file ``path``, atomically.

    Parameters
    ----------
    path : path
        Target file; replaced only once the new file is complete and flushed.
    sim : Simulation
        The simulation (finished or not: a loaded one can continue, bit for bit).
    attrs : dict, optional
        Extra root attributes (str, numbers or bool) written in the same atomic step.
    compress : bool
        gzip the large datasets (default); False writes faster (checkpoints).
    train : discrete.waves.Train, optional
        The solitary waves of the final state, written as the group ``train`` (module
        docstring); ValueError unless split at the simulation's time ``sim.t``.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    if not isinstance(sim, Simulation):
        raise ValueError(f"save() takes a Simulation (got {type(sim).__name__})")
    if train is not None and (not isinstance(train, Train) or train.t != sim.t):
        raise ValueError(f"train must be a discrete.waves.Train of the simulation's state "
                         f"at t = {sim.t!r} s (got {train!r:.80})")
    path = Path(path)
    with integrity.sealed_hdf5(path) as f:  # atomic and sealed (theory.integrity)
        _write(f, sim.saved(), compress)
        if train is not None:
            _write_train(f, train)
        for key, value in (attrs or {}).items():
            f.attrs[key] = value
    return path


_SCALARS = ("dt", "steps", "t", "t0", "energy0", "energy_drift", "wall_left", "wall_right",
            "drift_tolerance", "chunk", "active_window", "default_threshold", "integrator",
            "drag", "dissipation_rate0", "dt_default", "dt_source", "rtol", "rtol_estimate",
            "rtol_order", "rtol_probe_steps", "rtol_maxima")
"""Root attributes taken from :attr:`SavedSimulation.attrs`."""


def _write(f: h5py.File, saved: SavedSimulation, compress: bool) -> None:
    """Write a :class:`SavedSimulation` into the open file ``f`` (module docstring)."""
    a = f.attrs
    a["format"] = FORMAT
    a["package_version"] = _version()
    method = get_integrator(str(saved.attrs.get("integrator", "verlet")))
    a["solver"] = f"discrete DEM, {method.name} ({method.reference})"
    for key in _SCALARS:
        if key in saved.attrs:
            a[key] = saved.attrs[key]
    a["contact_law"] = json.dumps(saved.law.to_dict())
    a["contact_law_description"] = saved.law.describe()
    a["chain_params"] = json.dumps(saved.chain.params)
    a["recording"] = json.dumps(saved.recording.to_dict())
    a["pending_events"] = json.dumps([event_to_dict(e) for e in saved.pending])
    units = units_for(saved.law)
    a["units"] = json.dumps(units)
    g = f.create_group("chain")
    for name in ("mass", "k", "delta0", "diameter", "section"):
        _ds(g, name, getattr(saved.chain, name), compress, units)
    g = f.create_group("state")
    for name, arr in saved.state.items():
        _ds(g, name, arr, compress)
    rec = saved.record
    g = f.create_group("record")
    for name, arr in rec.arrays().items():
        _ds(g, name, arr, compress)
    if rec.vmax is not None:
        _ds(g, "vmax", rec.vmax, compress)
        _ds(g, "umax", rec.umax, compress)
    if rec.overlap_max is not None:
        _ds(g, "overlap_max", rec.overlap_max, compress)
    if rec.vmax_refined is not None:
        for name in ("vmax_refined", "vmax_time", "peak_state"):
            _ds(g, name, getattr(rec, name), compress)
    g.attrs["energy_coarsen"] = rec.energy_coarsen
    g.attrs["wall_forces"] = bool(rec.wall_forces)
    sg = f.create_group("snapshots")
    for i, s in enumerate(rec.snapshots):
        h = sg.create_group(f"{i:05d}")
        h.attrs["label"], h.attrs["t"], h.attrs["step"] = s.label, s.t, s.step
        for name in ("u", "v", "overlaps"):
            _ds(h, name, getattr(s, name), compress)


def _write_train(f: h5py.File, train: Train) -> None:
    """The group ``train`` (module docstring)."""
    g = f.create_group("train")
    for key, value in train.params().items():
        g.attrs[key] = value
    g.attrs["count"] = len(train)
    for name, arr in train.arrays().items():
        _ds(g, name, arr, units=TRAIN_FIELDS)


def _check_format(f: h5py.File, path: Path) -> None:
    """Refuse a file whose ``format`` attribute is not :data:`FORMAT`, naming both."""
    fmt = f.attrs.get("format")
    if isinstance(fmt, bytes):
        fmt = fmt.decode()
    if fmt != FORMAT:
        raise ValueError(f"{path} is not a {FORMAT} file (format {fmt!r})")


def load_train(path: str | os.PathLike) -> Train | None:
    """The solitary waves stored with a run (the group ``train``), or None if it has none.

    Read like :func:`load`: the file's integrity seal is verified first, and a missing
    field or attribute, a wrong unit, arrays of different lengths or a ``count`` that is
    not their length is a :class:`ValueError` naming the file and the part.
    """
    path = Path(path)
    with integrity.open_hdf5(path, what=f"result file ({FORMAT})") as f:
        _check_format(f, path)
        if "train" not in f:
            return None
        r = _Reader(f)
        try:
            g = r.group("train")
            arrays = {name: r.data(name, g) for name in TRAIN_FIELDS}
            for name, unit in TRAIN_FIELDS.items():
                got = r.attr("units", g[name])
                got = got.decode() if isinstance(got, bytes) else str(got)
                if got != unit:
                    raise ValueError(f"units {got!r}, expected {unit!r}")
            params = {key: r.attr(key, g) for key in ("t", "threshold", "valley", "lo", "hi")}
            count = int(r.attr("count", g))
            r.where = "group /train"
            train = Train.from_arrays(arrays, params)
            if len(train) != count:
                raise ValueError(f"count {count} but {len(train)} waves stored")
            return train
        except (KeyError, ValueError, TypeError, IndexError) as exc:
            detail = exc.args[0] if isinstance(exc, KeyError) and exc.args else exc
            raise ValueError(f"{path}: damaged or incomplete {FORMAT} file ({r.where}): "
                             f"{detail}") from None


class _Reader:
    """Reads one file, naming the object being read when something is missing or bad."""

    def __init__(self, f: h5py.File) -> None:
        self.f = f
        self.where = "the file"

    def attr(self, key: str, obj=None):
        obj = self.f if obj is None else obj
        self.where = f"attribute {key!r} of {obj.name}"
        if key not in obj.attrs:
            raise KeyError(f"missing {self.where}")
        return obj.attrs[key]

    def json(self, key: str):
        return json.loads(self.attr(key))

    def data(self, name: str, group: h5py.Group | None = None) -> np.ndarray:
        g = self.f if group is None else group
        full = f"{g.name.rstrip('/')}/{name}"
        self.where = f"dataset {full}"
        if name not in g or not isinstance(g[name], h5py.Dataset):
            raise KeyError(f"missing {self.where}")
        return g[name][()]

    def group(self, name: str) -> h5py.Group:
        self.where = f"group /{name}"
        if name not in self.f or not isinstance(self.f[name], h5py.Group):
            raise KeyError(f"missing {self.where}")
        return self.f[name]


def load(path: str | os.PathLike, *, threads: int | None = None) -> Simulation:
    """Read a file written by :func:`save`; returns a Simulation that can continue.

    Continuing the loaded simulation gives bit for bit what continuing the saved one
    would have given (``tests/test_reliability_checkpoint.py``).

    Parameters
    ----------
    path : path
        The file.
    threads : int, optional
        Kernel threads of the returned Simulation (a property of the machine, not of
        the run: not stored; results are bitwise identical for every value).

    Raises
    ------
    ValueError
        Naming ``path`` and the cause, if the file is missing, fails its integrity seal
        (:class:`theory.integrity.IntegrityError`: changed, truncated, not sealed), is
        not a :data:`FORMAT` file, or has a missing or inconsistent part.
    """
    path = Path(path)
    with integrity.open_hdf5(path, what=f"result file ({FORMAT})") as f:
        _check_format(f, path)
        r = _Reader(f)
        try:
            return _read(r, threads)
        except (OSError, KeyError, ValueError, TypeError, IndexError, RuntimeError,
                json.JSONDecodeError) as exc:
            detail = exc.args[0] if isinstance(exc, KeyError) and exc.args else exc
            raise ValueError(f"{path}: damaged or incomplete {FORMAT} file ({r.where}): "
                             f"{detail}") from None


def _read(r: _Reader, threads: int | None) -> Simulation:
    c = r.group("chain")
    chain = Chain(r.data("mass", c), r.data("k", c), r.data("delta0", c),
                  r.data("diameter", c), r.data("section", c), r.json("chain_params"))
    recording = Recording.from_dict(r.json("recording"))
    law = law_from_dict(r.json("contact_law")) if "contact_law" in r.f.attrs else None
    s = r.group("state")
    state = {name: r.data(name, s) for name in ("u", "v", "a")}
    for name in ("dissipated", "delta_expected"):  # optional (older files)
        if name in s:
            state[name] = r.data(name, s)
    attrs = {}
    for key in _SCALARS:
        if key in r.f.attrs:
            value = r.attr(key)
            attrs[key] = value.decode() if isinstance(value, bytes) else value
    r.where = "the root attributes (dt, steps, t0, walls, drift_tolerance, chunk, ...)"
    for key in ("dt", "steps", "t0", "energy0", "wall_left", "wall_right",
                "drift_tolerance", "chunk", "active_window", "default_threshold"):
        if key not in attrs:
            raise KeyError(f"missing attribute {key!r} of /")
    g = r.group("record")
    rec = Record(series_grains=r.data("series_grains", g),
                 energy_coarsen=int(r.attr("energy_coarsen", g)),
                 sensor_grains=(r.data("sensor_grains", g) if "sensor_grains" in g
                                else np.zeros(0, np.int64)),
                 wall_forces=bool(g.attrs.get("wall_forces", False)))
    for name in ("sensor_force", "wall_force"):  # optional (older files)
        if name in g:
            data = r.data(name, g)
            setattr(rec, name, [data] if len(data) else [])
    if "overlap_max" in g:
        rec.overlap_max = r.data("overlap_max", g)
    series = r.data("series", g)
    rec.series_t = list(r.data("series_t", g))
    rec.series = [series] if len(series) else []
    e_grid = [r.data(name, g) for name in ("energy_t", "energy_kinetic", "energy_potential")]
    if any(len(x) for x in e_grid):  # (the grid's storage: the arrays read, no copy;
        rec.energy.extend(*e_grid)   # ValueError for inconsistent shapes)
    rec.monitor_t = list(r.data("monitor_t", g))
    rec.monitor_energy = list(r.data("monitor_energy", g))
    rec.monitor_shadow = list(r.data("monitor_shadow", g))
    rec.monitor_dissipated = (list(r.data("monitor_dissipated", g))
                              if "monitor_dissipated" in g else [0.0] * len(rec.monitor_t))
    if recording.maxima or "vmax" in g:
        rec.vmax, rec.umax = r.data("vmax", g), r.data("umax", g)
    if "vmax_refined" in g:  # (older files: none; the run continues without them)
        rec.vmax_refined, rec.vmax_time, rec.peak_state = (
            r.data(name, g) for name in ("vmax_refined", "vmax_time", "peak_state"))
    snaps = r.group("snapshots")
    for key in sorted(snaps):
        h = snaps[key]
        r.where = f"snapshot {h.name}"
        rec.snapshots.append(Snapshot(str(r.attr("label", h)), float(r.attr("t", h)),
                                      int(r.attr("step", h)), r.data("u", h), r.data("v", h),
                                      r.data("overlaps", h)))
    pending = [event_from_dict(e) for e in r.json("pending_events")]
    r.where = "the state (state/*, record/*, root attributes)"
    saved = SavedSimulation(attrs, chain, law if law is not None else HERTZ, state,
                            recording, rec, pending)
    return Simulation.restore(saved, threads=threads)



# -- xarray ---------------------------------------------------------------------------
XARRAY_EXTRA = 'pip install "hertzchain[xarray]"'
"""How to install the optional xarray dependency (the package's ``xarray`` extra)."""

_GRAIN = ("grain index, counted from 0 (with a striker, the striker is grain 0: "
          "docs/guide/cli.md, 'Grain indices')")
_CONTACT = ("contact index j, between grains j - 1 and j (0: the left wall, N: the "
            "right wall)")


def _import_xarray():
    try:
        import xarray
    except ImportError as exc:
        raise ImportError(f"to_xarray needs the optional dependency xarray, which is not "
                          f"installed: {XARRAY_EXTRA} (or pip install xarray)") from exc
    return xarray


def to_xarray(sim: Simulation, *, train: Train | None = None):
    """The recorded data of ``sim`` as an :class:`xarray.Dataset` (optional dependency).

    Dimensions (each with a coordinate): ``grain`` (0 … N-1, the documented grain
    index), ``contact`` (0 … N), ``time`` (the time-series rows, s), ``series_grain``
    and ``sensor`` (the recorded grains' indices), ``snapshot`` (with ``snapshot_time``,
    s, ``snapshot_label`` and ``snapshot_step``), ``energy_time`` and ``energy_block``
    (the energy grid's rows, s, and the first grain of each block of
    ``energy_coarsen`` grains), ``monitor_time`` (s), ``wall`` ("left", "right") and,
    with ``train``, ``wave`` (:class:`discrete.waves.Train`, in position order).
    Variables: the chain (``mass``, ``diameter``, ``section``; ``k``, ``delta0`` per
    contact), the final state (``u``, ``v``, ``overlap``), the running maxima, the
    snapshots, the time series, sensors and wall forces, the energy grid and monitor,
    and the train, each with ``units`` (those of :func:`units_for`; "1" for indices)
    and ``long_name``.  Dataset attributes: the run's parameters (``dt``, ``t``,
    ``steps``, ``energy0``, ``integrator``, …, the attributes :func:`save` writes) and
    ``contact_law``, ``chain_params``, ``recording`` (JSON) and ``units`` (JSON);
    booleans as 1/0, so that :meth:`xarray.Dataset.to_netcdf` writes it as it is.

    Values are the simulation's, bit for bit (copies).  ImportError naming the extra
    (:data:`XARRAY_EXTRA`) when xarray is not installed.
    """
    xr = _import_xarray()
    if not isinstance(sim, Simulation):
        raise ValueError(f"to_xarray() takes a Simulation (got {type(sim).__name__})")
    if train is not None and not isinstance(train, Train):
        raise ValueError(f"train must be a discrete.waves.Train (got {type(train).__name__})")
    saved = sim.saved()
    units = units_for(saved.law)
    ch, rec = saved.chain, saved.record
    n = ch.n
    data: dict = {}

    def var(name, dims, values, unit, long_name):
        data[name] = xr.Variable(dims, np.array(values, copy=True),
                                 {"units": unit, "long_name": long_name})

    coords = {
        "grain": xr.Variable("grain", np.arange(n), {"units": "1", "long_name": _GRAIN}),
        "contact": xr.Variable("contact", np.arange(n + 1),
                               {"units": "1", "long_name": _CONTACT}),
    }
    var("mass", "grain", ch.mass, units["mass"], "grain mass")
    var("diameter", "grain", ch.diameter, units["diameter"], "grain diameter")
    var("section", "grain", ch.section, units["section"],
        "section of the grain (-1: a striker)")
    var("k", "contact", ch.k, units["k"], "contact constant of F = k δ^n")
    var("delta0", "contact", ch.delta0, units["delta0"], "static overlap δ0")
    var("u", "grain", saved.state["u"], units["u"],
        "displacement from static equilibrium at t")
    var("v", "grain", saved.state["v"], units["v"], "grain velocity at t")
    var("overlap", "contact", sim.overlaps(), units["overlaps"], "contact overlap at t")
    if rec.vmax is not None:
        var("vmax", "grain", rec.vmax, units["vmax"],
            "running maximum of the grain velocity (sampled at the steps)")
        var("umax", "grain", rec.umax, units["umax"], "running maximum of the displacement")
    if rec.vmax_refined is not None:
        var("vmax_refined", "grain", rec.vmax_refined, units["vmax_refined"],
            "refined running maximum of the grain velocity (between the steps)")
        var("vmax_time", "grain", rec.vmax_time, units["vmax_time"],
            "time of the refined maximum")
    if rec.overlap_max is not None:
        var("overlap_max", "contact", rec.overlap_max, units["overlap_max"],
            "running maximum of the contact overlap")
    snaps = rec.snapshots
    if snaps:
        coords["snapshot"] = xr.Variable("snapshot", np.arange(len(snaps)),
                                         {"units": "1", "long_name": "snapshot number"})
        coords["snapshot_time"] = xr.Variable("snapshot", [s.t for s in snaps],
                                              {"units": "s", "long_name": "snapshot time"})
        coords["snapshot_label"] = xr.Variable("snapshot", [s.label for s in snaps],
                                               {"long_name": "snapshot event"})
        coords["snapshot_step"] = xr.Variable("snapshot", [s.step for s in snaps],
                                              {"units": "1", "long_name": "snapshot step"})
        var("snapshot_u", ("snapshot", "grain"), [s.u for s in snaps], units["u"],
            "displacement at the snapshot")
        var("snapshot_v", ("snapshot", "grain"), [s.v for s in snaps], units["v"],
            "grain velocity at the snapshot")
        var("snapshot_overlap", ("snapshot", "contact"), [s.overlaps for s in snaps],
            units["overlaps"], "contact overlap at the snapshot")
    a = rec.arrays()
    if a["series_t"].size or rec.series_grains.size:
        coords["time"] = xr.Variable("time", a["series_t"],
                                     {"units": "s", "long_name": "time of the series rows"})
    if rec.series_grains.size:
        coords["series_grain"] = xr.Variable("series_grain", a["series_grains"],
                                             {"units": "1", "long_name": _GRAIN})
        for q, (name, unit, text) in enumerate((
                ("series_u", units["u"], "displacement"),
                ("series_v", units["v"], "grain velocity"),
                ("series_overlap_left", units["overlaps"], "overlap of the left contact"),
                ("series_overlap_right", units["overlaps"], "overlap of the right contact"))):
            var(name, ("time", "series_grain"), a["series"][:, :, q], unit, text)
    if rec.sensor_grains.size:
        coords["sensor"] = xr.Variable("sensor", a["sensor_grains"],
                                       {"units": "1", "long_name": _GRAIN})
        var("sensor_force", ("time", "sensor"), a["sensor_force"], units["sensor_force"],
            "embedded sensor: mean of the grain's two contact forces")
    if rec.wall_forces:
        coords["wall"] = xr.Variable("wall", ["left", "right"], {"long_name": "wall"})
        var("wall_force", ("time", "wall"), a["wall_force"], units["wall_force"],
            "force on the wall")
    if len(rec.energy):
        c = int(rec.energy_coarsen)
        coords["energy_time"] = xr.Variable("energy_time", a["energy_t"],
                                            {"units": "s", "long_name": "energy grid rows"})
        coords["energy_block"] = xr.Variable(
            "energy_block", np.arange(a["energy_kinetic"].shape[1]) * c,
            {"units": "1", "long_name": f"first grain of a block of {c} grains ({_GRAIN})"})
        var("energy_kinetic", ("energy_time", "energy_block"), a["energy_kinetic"],
            units["energy_kinetic"], "kinetic energy ½mv² of the block")
        var("energy_potential", ("energy_time", "energy_block"), a["energy_potential"],
            units["energy_potential"], "contact energy of the block (half of each contact)")
    coords["monitor_time"] = xr.Variable("monitor_time", a["monitor_t"],
                                         {"units": "s", "long_name": "energy monitor times"})
    var("monitor_energy", "monitor_time", a["monitor_energy"], units["monitor_energy"],
        "total energy E")
    var("monitor_shadow", "monitor_time", a["monitor_shadow"], units["monitor_shadow"],
        "velocity Verlet's modified energy")
    var("monitor_dissipated", "monitor_time", a["monitor_dissipated"],
        units["monitor_dissipated"], "energy dissipated since the start")
    if train is not None:
        coords["wave"] = xr.Variable("wave", np.arange(len(train)),
                                     {"units": "1", "long_name": "wave of the train, in "
                                      "position order"})
        texts = {"position": f"peak position ({_GRAIN})", "start": "first grain",
                 "stop": "one past the last grain",
                 "velocity_max": "peak grain velocity of the exact wave of its energy",
                 "amplitude": "peak dynamic overlap of that wave", "energy": "wave energy",
                 "speed": "speed of that wave", "sampled_velocity": "sampled peak velocity"}
        for name, arr in train.arrays().items():
            var(f"train_{name}", "wave", arr, TRAIN_FIELDS[name], texts[name])
    # (netCDF has no booleans: True/False as 1/0; None, an rtol not asked for, left out)
    attrs = {key: (int(v) if isinstance(v, bool | np.bool_) else v)
             for key, v in saved.attrs.items() if key in _SCALARS and v is not None}
    attrs.update(format=FORMAT, package_version=_version(),
                 contact_law=json.dumps(saved.law.to_dict()),
                 contact_law_description=saved.law.describe(),
                 chain_params=json.dumps(saved.chain.params),
                 recording=json.dumps(saved.recording.to_dict()),
                 units=json.dumps(units), n_grains=int(n),
                 energy_coarsen=int(rec.energy_coarsen))
    if train is not None:
        attrs.update({f"train_{k}": v for k, v in train.params().items()})
    return xr.Dataset(data, coords=coords, attrs=attrs)
