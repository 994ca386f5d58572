"""HDF5 output of a :class:`~discrete.simulation.Simulation` (h5py).

Layout: root attributes ``format``, ``package_version``, ``solver``, ``dt`` (s),
``steps``, ``t`` (s), ``t0`` (s), ``energy0`` (J), ``energy_drift``, ``wall_left``,
``wall_right`` (m), ``chain_params`` and ``recording`` (JSON) and ``units`` (JSON:
the unit of every dataset); groups ``chain`` (mass, k, delta0, diameter, section),
``state`` (u, v, a), ``record`` (series, energy grid, monitor, maxima) and
``snapshots/<i>`` (u, v, overlaps with attributes label, t, step).  Datasets are
chunked and gzip-compressed.  The file is written to a temporary file in the target
directory and renamed when complete (``os.replace``), so a reader never sees a partial
file.
"""

from __future__ import annotations

import dataclasses
import importlib.metadata
import json
import os
import tempfile
from pathlib import Path

import h5py
import numpy as np

from .chain import Chain
from .recording import AtTime, Record, Recording, Snapshot, WaveAt
from .simulation import Simulation

__all__ = ["save", "load", "UNITS"]

FORMAT = "hertzchain.discrete/1"
UNITS = {
    "t": "s", "dt": "s", "t0": "s", "energy0": "J", "wall_left": "m", "wall_right": "m",
    "mass": "kg", "k": "N/m^(3/2)", "delta0": "m", "diameter": "m", "section": "1",
    "u": "m", "v": "m/s", "a": "m/s^2", "overlaps": "m", "series": "m, m/s, m, m",
    "series_t": "s", "energy_t": "s", "energy_kinetic": "J", "energy_potential": "J",
    "monitor_t": "s", "monitor_energy": "J", "monitor_shadow": "J", "vmax": "m/s", "umax": "m",
}


def _version() -> str:
    try:
        return importlib.metadata.version("hertzchain")
    except importlib.metadata.PackageNotFoundError:  # pragma: no cover
        return "unknown"


def _ds(group: h5py.Group, name: str, data) -> None:
    data = np.asarray(data)
    if data.size >= 64:
        group.create_dataset(name, data=data, chunks=True, compression="gzip",
                             compression_opts=4, shuffle=True)
    else:
        group.create_dataset(name, data=data)
    if name in UNITS:
        group[name].attrs["units"] = UNITS[name]


def _events_json(rec: Recording) -> list:
    out = []
    for e in rec.events():
        out.append({"type": type(e).__name__, **dataclasses.asdict(e)})
    return out


def save(path: str | os.PathLike, sim: Simulation) -> Path:
    """Write ``sim`` (chain, state, recording, record) to the HDF5 file ``path``."""
    if not isinstance(sim, Simulation):
        raise ValueError(f"save() takes a Simulation (got {type(sim).__name__})")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".", suffix=".tmp")
    os.close(fd)
    try:
        with h5py.File(tmp, "w") as f:
            a = f.attrs
            a["format"] = FORMAT
            a["package_version"] = _version()
            a["solver"] = "velocity Verlet (discrete.kernels.run_chunk)"
            for key in ("dt", "steps", "t", "t0", "energy0", "wall_left", "wall_right",
                        "drift_tolerance", "chunk"):
                a[key] = getattr(sim, key)
            a["active_window"] = sim.active_window
            a["default_threshold"] = sim._default_threshold
            a["energy_drift"] = sim.energy_drift
            a["chain_params"] = json.dumps(sim.chain.params)
            rec = sim.recording
            a["recording"] = json.dumps({
                "snapshots": _events_json(rec), "series_grains": [int(g) for g in
                                                                  rec.series_grains],
                "series_every": int(rec.series_every), "maxima": bool(rec.maxima),
                "energy_every": rec.energy_every, "energy_coarsen": int(rec.energy_coarsen),
                "monitor_every": int(rec.monitor_every)})
            a["pending_events"] = json.dumps([{"type": type(e).__name__,
                                               **dataclasses.asdict(e)}
                                              for e in sim._pending])
            a["units"] = json.dumps(UNITS)
            g = f.create_group("chain")
            for name in ("mass", "k", "delta0", "diameter", "section"):
                _ds(g, name, getattr(sim.chain, name))
            g = f.create_group("state")
            for name in ("u", "v", "a"):
                _ds(g, name, getattr(sim, name))
            g = f.create_group("record")
            for name, arr in sim.record.arrays().items():
                _ds(g, name, arr)
            if sim.record.vmax is not None:
                _ds(g, "vmax", sim.record.vmax)
                _ds(g, "umax", sim.record.umax)
            g.attrs["energy_coarsen"] = sim.record.energy_coarsen
            sg = f.create_group("snapshots")
            for i, s in enumerate(sim.record.snapshots):
                h = sg.create_group(f"{i:05d}")
                h.attrs["label"], h.attrs["t"], h.attrs["step"] = s.label, s.t, s.step
                for name in ("u", "v", "overlaps"):
                    _ds(h, name, getattr(s, name))
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
    return path


def _event(d: dict):
    d = dict(d)
    kind = d.pop("type")
    return AtTime(**d) if kind == "AtTime" else WaveAt(**d)


def load(path: str | os.PathLike) -> Simulation:
    """Read a file written by :func:`save`; returns a Simulation that can continue."""
    with h5py.File(path, "r") as f:
        a = f.attrs
        if a.get("format") != FORMAT:
            raise ValueError(f"{path} is not a {FORMAT} file (format {a.get('format')!r})")
        c = f["chain"]
        chain = Chain(c["mass"][()], c["k"][()], c["delta0"][()], c["diameter"][()],
                      c["section"][()], json.loads(a["chain_params"]))
        r = json.loads(a["recording"])
        recording = Recording(snapshots=[_event(e) for e in r["snapshots"]],
                              series_grains=r["series_grains"], series_every=r["series_every"],
                              maxima=r["maxima"], energy_every=r["energy_every"],
                              energy_coarsen=r["energy_coarsen"],
                              monitor_every=r["monitor_every"])
        s = f["state"]
        sim = Simulation(chain, s["u"][()], s["v"][()], dt=float(a["dt"]),
                         wall_left=float(a["wall_left"]), wall_right=float(a["wall_right"]),
                         record=recording, t=float(a["t0"]),
                         active_window=bool(a["active_window"]),
                         drift_tolerance=float(a["drift_tolerance"]), chunk=int(a["chunk"]))
        sim.steps = int(a["steps"])
        sim.a[:] = s["a"][()]
        sim.energy0 = float(a["energy0"])
        sim._default_threshold = float(a["default_threshold"])
        sim._pending = [_event(e) for e in json.loads(a["pending_events"])]
        g = f["record"]
        rec = Record(series_grains=g["series_grains"][()],
                     energy_coarsen=int(g.attrs["energy_coarsen"]))
        rec.series_t = list(g["series_t"][()])
        rec.series = [g["series"][()]] if len(g["series"]) else []
        rec.energy_t = list(g["energy_t"][()])
        rec.energy_kinetic = list(g["energy_kinetic"][()])
        rec.energy_potential = list(g["energy_potential"][()])
        rec.monitor_t = list(g["monitor_t"][()])
        rec.monitor_energy = list(g["monitor_energy"][()])
        rec.monitor_shadow = list(g["monitor_shadow"][()])
        if "vmax" in g:
            rec.vmax, rec.umax = g["vmax"][()], g["umax"][()]
        for key in sorted(f["snapshots"]):
            h = f["snapshots"][key]
            rec.snapshots.append(Snapshot(str(h.attrs["label"]), float(h.attrs["t"]),
                                          int(h.attrs["step"]), h["u"][()], h["v"][()],
                                          h["overlaps"][()]))
        sim.record = rec
    return sim
