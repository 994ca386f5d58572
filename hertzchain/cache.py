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
