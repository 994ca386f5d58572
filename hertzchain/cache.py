"""Results cached by their parameters, written atomically.

A result is identified by the canonical JSON of its parameters (sorted keys, floats
in ``repr``) together with :data:`CACHE_SCHEMA`; its file name carries the first 12
hex digits of the SHA-256 of that text.  Files are written to a temporary name in the
target directory and renamed when complete (:func:`atomic_path`), so a reader never
sees a half-written file and a crash leaves either the old file or none.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import tempfile
from collections.abc import Iterator, Mapping
from pathlib import Path

import numpy as np

__all__ = ["CACHE_SCHEMA", "canonical_json", "param_hash", "cache_path", "atomic_path"]

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


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it onto ``path`` on success.

    On an exception the temporary file is removed and ``path`` is left untouched.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    # mkstemp creates 0600; give the result the permissions of a normally created file
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp_path, 0o666 & ~umask)
    try:
        yield tmp_path
        os.replace(tmp_path, path)
    finally:
        if tmp_path.exists():
            tmp_path.unlink()
