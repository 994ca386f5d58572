"""HDF5 output of a :class:`~discrete.simulation.Simulation` (h5py).

Layout: root attributes ``format``, ``package_version``, ``solver``, ``dt`` (s),
``steps``, ``t`` (s), ``t0`` (s), ``energy0`` (J), ``energy_drift``, ``wall_left``,
``wall_right`` (m), ``chain_params``, ``recording`` and ``contact_law`` (JSON,
:meth:`theory.laws.ContactLaw.to_dict`; absent means Hertz), ``drag`` (1/s) and
``units`` (JSON: the unit of every dataset); groups ``chain`` (mass, k, delta0,
diameter, section), ``state`` (u, v, a; optional ``dissipated``, the energy booked per
contact, and ``delta_expected``, the largest expected overlaps of the run's initial
state, with the attribute ``dt_default``), ``record`` (series, energy grid, monitor,
maxima) and ``snapshots/<i>`` (u, v, overlaps with attributes label, t, step).  What is
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

__all__ = ["save", "load", "UNITS", "FORMAT", "contact_constant_unit", "units_for"]

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
         compress: bool = True) -> Path:
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

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    if not isinstance(sim, Simulation):
        raise ValueError(f"save() takes a Simulation (got {type(sim).__name__})")
    path = Path(path)
    with integrity.sealed_hdf5(path) as f:  # atomic and sealed (theory.integrity)
        _write(f, sim.saved(), compress)
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
        fmt = f.attrs.get("format")
        if isinstance(fmt, bytes):
            fmt = fmt.decode()
        if fmt != FORMAT:
            raise ValueError(f"{path} is not a {FORMAT} file (format {fmt!r})")
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

