"""Reading result files for ``hertzchain info`` and ``hertzchain plot``.

Discrete runs are written by :func:`discrete.io.save` (attribute ``format``); the runner
adds the scenario and the summary as JSON attributes.  Every file the package writes
is sealed (:mod:`theory.integrity`) and :func:`describe` verifies it exactly as
:func:`discrete.io.load` does: a file that is missing, unsealed, changed in any byte,
truncated, or damaged inside gets a clear :class:`ValueError` naming the file rather
than an h5py traceback.  The PNG of :func:`plot_file` is written atomically.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import tempfile
from pathlib import Path

import numpy as np

from theory import integrity

from .cache import atomic_path
from .measure import interfaces

__all__ = ["open_result", "describe", "plot_file", "check_output"]


DISCRETE_DATASETS = ("chain/mass", "chain/k", "chain/delta0", "chain/diameter",
                     "chain/section", "state/u", "state/v", "state/a", "record/series_t",
                     "record/series", "record/energy_t", "record/energy_kinetic",
                     "record/energy_potential", "record/monitor_t", "record/monitor_energy",
                     "record/monitor_shadow")
"""Datasets every file of :func:`discrete.io.save` has (checked by :func:`describe`)."""


def check_output(path: str | os.PathLike, kind: str = "file", flag: str = "--out") -> Path:
    """Check before any work that ``path`` can be written; returns it as a Path.

    ``kind = "file"``: ``path`` must not be a directory and its directory must be (or
    be creatable in) a writable place; ``"dir"``: ``path`` must not be a file and must
    be (or be creatable in) a writable place.  Writability is tested by creating and
    removing a probe file in the nearest existing directory (``os.access`` is wrong for
    root and read-only mounts).  Nothing is created.

    Raises
    ------
    OSError
        Naming ``flag`` and the path: an existing directory where a file is expected
        (or the reverse), a file on the way, a read-only or otherwise unwritable place.
    """
    path = Path(path)
    if kind not in ("file", "dir"):
        raise ValueError(f"kind must be 'file' or 'dir' (got {kind!r})")
    if kind == "file" and path.is_dir():
        raise IsADirectoryError(errno.EISDIR, f"{flag} {path} is a directory; give a file "
                                f"name (e.g. {path / 'run.h5'})")
    if kind == "dir" and path.exists() and not path.is_dir():
        raise NotADirectoryError(errno.ENOTDIR, f"{flag} {path} is a file; give a "
                                 "directory (created if absent)")
    place = path.parent if kind == "file" else path
    while not place.exists():
        if place.parent == place:
            break
        place = place.parent
    if place.exists() and not place.is_dir():
        raise NotADirectoryError(errno.ENOTDIR, f"{flag} {path}: {place} is a file, not a "
                                 "directory")
    try:
        fd, probe = tempfile.mkstemp(prefix=".hertzchain-probe-", dir=place)
    except OSError as exc:
        raise type(exc)(exc.errno, f"{flag} {path} cannot be written: {place}: "
                        f"{exc.strerror} (checked before the run)") from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(probe)
    return path


def open_result(path: str | Path):
    """Verify a result file's seal and open it read-only (a context manager).

    The same check as :func:`discrete.io.load` (:func:`theory.integrity.open_hdf5`):
    :class:`theory.integrity.IntegrityError` (a ``ValueError``) naming the file if it
    is missing, unsealed, changed, truncated or not HDF5.
    """
    return integrity.open_hdf5(path, what="result file")


def _attr(value):
    if isinstance(value, bytes):
        value = value.decode()
    if isinstance(value, str) and value[:1] in "{[":
        try:
            return json.loads(value)
        except json.JSONDecodeError:
            return value
    if isinstance(value, np.generic):
        return value.item()
    return value


def describe(path: str | Path) -> str:
    """A readable description: attributes (parameters, summary) and datasets.

    Raises
    ------
    ValueError
        Naming the file, if it is not a readable HDF5 file, an object in it cannot be
        read, or a discrete run (``format`` attribute) lacks one of
        :data:`DISCRETE_DATASETS`.
    """
    lines = [f"{path}"]
    with open_result(path) as f:
        try:
            _describe(f, lines)
        except (OSError, RuntimeError, KeyError, TypeError) as exc:
            raise ValueError(f"{path}: damaged HDF5 file (an object cannot be read): "
                             f"{exc}") from None
        fmt = _attr(f.attrs.get("format", ""))
        if isinstance(fmt, str) and fmt.startswith("hertzchain.discrete/"):
            missing = [name for name in DISCRETE_DATASETS if name not in f]
            if missing:
                raise ValueError(f"{path}: incomplete discrete run ({fmt}): missing "
                                 f"dataset(s) {missing}")
    return "\n".join(lines)


def _describe(f, lines: list[str]) -> None:
    for key in sorted(f.attrs):
        val = _attr(f.attrs[key])
        if isinstance(val, dict):
            lines.append(f"  {key}:")
            lines += [f"    {k}: {v}" for k, v in val.items()]
        else:
            lines.append(f"  {key}: {val}")
    lines.append("  datasets:")

    import h5py  # (not at import: start-up of ``hertzchain run``)

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            lines.append(f"    {name} {obj.shape} {obj.dtype}")

    f.visititems(visit)


def plot_file(path: str | Path, out: str | Path | None = None) -> Path:
    """Plot a discrete run: velocity profile; if recorded energy map, forces, strain maxima.

    Panels: the final grain velocities; the energy space–time grid, the wall and sensor
    forces and the per-contact strain maxima when they were recorded.
    """
    import matplotlib

    matplotlib.use("agg")
    import matplotlib.pyplot as plt

    from discrete.io import load

    from .plotting import plot_forces, plot_grain_profile, plot_spacetime, plot_strain_maxima

    path = Path(path)
    sim = load(path)
    arr = sim.record.arrays()
    has_grid = arr["energy_kinetic"].shape[0] > 1
    has_forces = arr["sensor_force"].size > 0 or arr["wall_force"].size > 0
    has_strain = sim.record.overlap_max is not None
    ncol = 1 + has_grid + has_forces + has_strain
    fig, axes = plt.subplots(1, ncol, figsize=(5.5 * ncol, 4), squeeze=False)
    ifaces = interfaces(sim.chain)  # (a striker grain is no section: not grain 1)
    iface = ifaces[0] if ifaces else None
    plot_grain_profile(axes[0, 0], sim.v, interface=iface, ylabel="grain velocity (m/s)")
    axes[0, 0].set_title(f"t = {sim.t * 1e3:.4g} ms")
    if has_grid:
        e = arr["energy_kinetic"] + arr["energy_potential"]
        coarsen = sim.record.energy_coarsen  # (columns of the grid: blocks of grains)
        plot_spacetime(axes[0, 1], arr["energy_t"], e,
                       interface=None if iface is None else iface // coarsen,
                       label="grain energy (J)", cmap="viridis")
    if has_forces:  # what sensors measure (discrete.Recording sensors, wall_forces)
        cols, labels = [], []
        if arr["wall_force"].size:
            cols += [arr["wall_force"][:, 0], arr["wall_force"][:, 1]]
            labels += ["left wall", "right wall"]
        for q, g in enumerate(arr["sensor_grains"]):
            cols.append(arr["sensor_force"][:, q])
            labels.append(f"sensor at grain {int(g)}")
        plot_forces(axes[0, 1 + has_grid], arr["series_t"], np.stack(cols, axis=1), labels)
    if has_strain:  # per-contact strain maxima (discrete.Recording strain_maxima)
        d = np.r_[sim.chain.diameter[0], sim.chain.diameter]  # contact j: grain j-1's (wall: 0)
        plot_strain_maxima(axes[0, -1], (sim.record.overlap_max - sim.chain.delta0) / d,
                           interface=iface)
    fig.tight_layout()
    out = Path(out) if out is not None else path.with_suffix(".png")
    try:
        with atomic_path(out) as tmp:
            fig.savefig(tmp, dpi=120, format="png")
    finally:
        plt.close(fig)
    return out
