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
import hashlib
import inspect
import marshal
import os
import sys
import tempfile
from pathlib import Path

__all__ = ["configure", "default_cache_dir", "cache_is_warm", "keyed_njit", "source_digest"]

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


def source_digest(*objects) -> str:
    """SHA-256 of the source files of ``objects`` (modules, classes or functions).

    Part of the key of a :func:`keyed_njit` kernel, so that editing a source the kernel
    is compiled from recompiles it.  An object whose file cannot be read (defined by
    ``exec``) contributes the bytecode of its functions instead.
    """
    h = hashlib.sha256()
    for obj in objects:
        try:
            with open(inspect.getsourcefile(obj), "rb") as f:  # type: ignore[arg-type]
                h.update(f.read())
        except (TypeError, OSError):
            funcs = vars(obj).items() if isinstance(obj, type) else [("", obj)]
            for name, attr in sorted(funcs, key=lambda kv: kv[0]):
                code = getattr(getattr(attr, "__func__", attr), "__code__", None)
                if code is not None:
                    h.update(name.encode() + marshal.dumps(code))
    return h.hexdigest()


def keyed_njit(py_func, key: str, *, cache: bool = True, **options):
    """``numba.njit(**options)(py_func)`` for a closure, with a disk cache keyed by ``key``.

    numba keys a closure's cache entry by a pickle of the values it closes over; when
    those are compiled functions (a contact law's pieces) the pickle holds a per-process
    id, so every process would miss.  Here the entry is keyed by the function's bytecode
    and ``key`` instead, which must name everything the compiled code depends on (e.g.
    a law's :meth:`~theory.laws.ContactLaw.key` and a :func:`source_digest` of the
    sources).  The function's name gets a suffix from ``key``, so that closures of the
    same name compiled for different keys (and loaded from the cache into one process)
    never share a symbol.  ``cache=False``: only the renaming (inner functions).
    """
    import numba

    configure()
    tag = hashlib.sha256(key.encode()).hexdigest()[:12]
    py_func.__qualname__ = f"{py_func.__qualname__}_K{tag}"
    disp = numba.njit(**options)(py_func)
    if cache:
        try:
            from numba.core.caching import FunctionCache

            class _KeyedCache(FunctionCache):
                def _index_key(self, sig, codegen):
                    code = self._py_func.__code__.co_code
                    digest = hashlib.sha256(code + key.encode()).hexdigest()
                    return (sig, codegen.magic_tuple(), (digest, ""))

            disp._cache = _KeyedCache(py_func)
        except Exception:  # pragma: no cover - numba internals changed: run uncached
            pass
    return disp
