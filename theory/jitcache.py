"""Where compiled numba kernels are cached: a user cache directory, never the package.

The kernels of :mod:`discrete` and :mod:`continuum` are compiled with
``numba.njit(cache=True)``.  By default numba writes that cache into the
``__pycache__`` directory beside the source file, i.e. into the installed package
(``site-packages/discrete/__pycache__/``).  pip does not remove files it did not
install, so after ``pip install .`` and then ``pip install -e .`` an otherwise empty
``site-packages/discrete/`` directory is left behind, and Python imports it as a
namespace package in front of the editable install: ``import discrete`` then yields an
empty package.  The compiled cache therefore lives outside every installed package, in
the directory :func:`configure` chooses:

1. ``$NUMBA_CACHE_DIR`` if the user set it (numba's own setting, respected as is);
2. else ``$XDG_CACHE_HOME/hertzchain/numba`` (``~/.cache/hertzchain/numba`` when
   ``XDG_CACHE_HOME`` is unset; ``%LOCALAPPDATA%/hertzchain/numba`` on Windows);
3. else, if that directory cannot be created or written, a per-user directory in the
   system temporary directory.

Inside it numba keeps one subdirectory per source directory (named by a hash of its
path), so an installed copy and an editable checkout never share compiled files, and
deleting the directory only costs one recompilation (about 15 s).

Numba chooses a function's cache directory when the ``cache=True`` decorator runs, so
:func:`configure` must be called before the kernel modules define their functions:
each kernel module calls it first (``discrete/kernels.py``, ``continuum/_kernels.py``,
``continuum/_stepper.py``, ``hertzchain/sweep/synthetic.py``).  It also exports
``NUMBA_CACHE_DIR`` so that numba's configuration reloads and child processes (Dask
workers) use the same directory.

This module lives in :mod:`theory` because it is the one package that both
:mod:`discrete` and :mod:`continuum` may import; it imports numba only when called.
"""

from __future__ import annotations

import getpass
import os
import sys
import tempfile
from pathlib import Path

__all__ = ["configure", "default_cache_dir", "cache_is_warm"]

_ENV = "NUMBA_CACHE_DIR"


def default_cache_dir() -> Path:
    """The user cache directory for compiled kernels when ``NUMBA_CACHE_DIR`` is unset.

    Returns
    -------
    Path
        ``$XDG_CACHE_HOME/hertzchain/numba`` (``~/.cache/hertzchain/numba``), or
        ``%LOCALAPPDATA%/hertzchain/numba`` on Windows.  Not created here.
    """
    if sys.platform == "win32" and os.environ.get("LOCALAPPDATA"):
        base = Path(os.environ["LOCALAPPDATA"])
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "hertzchain" / "numba"


def _writable(path: Path) -> bool:
    try:
        path.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=path).close()
    except OSError:
        return False
    return True


def configure() -> str:
    """Point numba's kernel cache at a user cache directory (see the module docstring).

    Idempotent; a ``NUMBA_CACHE_DIR`` set by the user (or by an earlier call) is kept.
    Call it before any ``njit(cache=True)`` decorator of ours runs.

    Returns
    -------
    str
        The cache directory in use.
    """
    import numba

    path = os.environ.get(_ENV, "")
    if not path:
        cand = default_cache_dir()
        if not _writable(cand):
            try:
                user = getpass.getuser()
            except (KeyError, OSError):  # no user name (some containers)
                user = str(os.getuid()) if hasattr(os, "getuid") else "user"
            cand = Path(tempfile.gettempdir()) / f"hertzchain-numba-{user}"
        path = str(cand)
        os.environ[_ENV] = path
    if numba.config.CACHE_DIR != path:
        numba.config.reload_config()
    return path


def cache_is_warm(dispatcher) -> bool:
    """Whether calling ``dispatcher`` will most likely not compile (cheap file check).

    True if it already holds a compiled signature in this process, or if numba's cache
    index for it exists and is newer than its source file (numba recompiles when the
    source changed after the index was written).  A warm index can still miss the
    argument types or CPU of a new call: this is a hint for a progress message, not a
    guarantee.

    Parameters
    ----------
    dispatcher : numba.core.registry.CPUDispatcher
        A function decorated with ``numba.njit(cache=True)``.

    Returns
    -------
    bool
    """
    if dispatcher.signatures:
        return True
    cache = getattr(dispatcher, "_cache", None)
    path = getattr(cache, "cache_path", None)
    if not path:
        return False
    py = dispatcher.py_func
    # numba's file name drops '<' and '>' (closures: '<locals>')
    qualname = py.__qualname__.replace("<", "").replace(">", "")
    name = f"{Path(py.__code__.co_filename).stem}.{qualname}-"
    try:
        src = os.stat(py.__code__.co_filename).st_mtime
        return any(f.name.startswith(name) and f.suffix == ".nbi"
                   and f.stat().st_mtime >= src for f in Path(path).iterdir())
    except OSError:
        return False
