"""Results cached by their parameters, written atomically.

A result is identified by the canonical JSON of its parameters (sorted keys, floats
in ``repr``) together with :data:`CACHE_SCHEMA`; its file name carries the first 12
hex digits of the SHA-256 of that text.  Files are written to a temporary name in the
target directory and renamed when complete (:func:`atomic_path`, the one implementation
in :mod:`theory.integrity`), so a reader never sees a half-written file and a crash
leaves either the old file or none; files read back are sealed
(:func:`theory.integrity.sealed_hdf5`) and verified on read.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from theory.integrity import atomic_path

__all__ = ["CACHE_SCHEMA", "canonical_json", "param_hash", "cache_path", "atomic_path",
           "is_stale_temporary", "remove_stale_temporaries", "clear_settled_waves"]

CACHE_SCHEMA = 2
"""Bump when the meaning of cached results changes, to invalidate old files (2: the
summary says how the run ended, labels are None unless the waves separated)."""


def _default(obj):
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"cannot serialise {type(obj).__name__} in cache parameters")


def canonical_json(params: Mapping) -> str:
    """Deterministic JSON text of ``params`` (sorted keys, no whitespace)."""
    return json.dumps(params, sort_keys=True, separators=(",", ":"), default=_default)


def param_hash(params: Mapping) -> str:
    """First 12 hex digits of SHA-256 over the schema and the canonical parameters."""
    text = f"schema={CACHE_SCHEMA};" + canonical_json(params)
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def cache_path(directory: str | os.PathLike, stem: str, params: Mapping,
               suffix: str = ".h5") -> Path:
    """Path ``directory/<stem>-<hash><suffix>`` for a result with ``params``."""
    return Path(directory) / f"{stem}-{param_hash(params)}{suffix}"


def _pid_running(pid: int) -> bool:
    if pid == os.getpid():
        return False  # ours, from an earlier failed write of this process
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # another user's live process
    return True


def is_stale_temporary(tmp: str | os.PathLike, name: str | None = None) -> bool:
    """Whether ``.<name>.<pid>-<random>.tmp`` (:func:`atomic_path`) is a leftover.

    A leftover: its writer (the pid in the name) no longer runs, or the name has no pid
    (older writers).  With ``name`` given, a temporary of a longer file name
    (``<name>.ckpt``) is not judged (False).
    """
    tmp = Path(tmp)
    if not (tmp.name.startswith(".") and tmp.name.endswith(".tmp")):
        return False
    if name is not None:
        rest = tmp.name[len(name) + 2:-len(".tmp")]
        if "." in rest:
            return False
    else:
        rest = tmp.name[:-len(".tmp")].rsplit(".", 1)[-1]
    pid_text = rest.split("-", 1)[0]
    if "-" not in rest or not pid_text.isdigit():
        return True
    return not _pid_running(int(pid_text))


def remove_stale_temporaries(directory: str | os.PathLike) -> list[Path]:
    """Delete the leftover temporaries (:func:`is_stale_temporary`) in a cache directory.

    A process killed while writing a cached result or settled wave leaves its
    ``.<name>.<pid>-<random>.tmp``; a live writer's temporaries are kept.
    """
    return _remove(Path(directory), ".*.tmp", is_stale_temporary)


def clear_settled_waves(directory: str | os.PathLike) -> list[Path]:
    """Delete the cached settled waves (``settled_wave_*.npz``) of a directory (--force)."""
    return _remove(Path(directory), "settled_wave_*.npz", lambda p: True)


def _remove(directory: Path, pattern: str, wanted) -> list[Path]:
    """Delete the files of ``directory`` matching ``pattern`` for which ``wanted(path)``.

    A file another process removed first is skipped.  Returns the removed paths, sorted.
    """
    removed = []
    for p in sorted(directory.glob(pattern)) if directory.is_dir() else ():
        if wanted(p):
            try:
                p.unlink()
            except FileNotFoundError:
                continue
            removed.append(p)
    return removed
