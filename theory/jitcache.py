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
deleting the directory only costs one recompilation (:data:`KERNEL_FAMILIES`).

Numba chooses a function's cache directory when the ``cache=True`` decorator runs, so
:func:`configure` must be called before the kernel modules define their functions:
each kernel module calls it first (``discrete/kernels.py``, ``continuum/_kernels.py``,
``continuum/_stepper.py``, ``hertzchain/sweep/synthetic.py``).  It also exports
``NUMBA_CACHE_DIR`` so that numba's configuration reloads and child processes (Dask
workers) use the same directory.

A compilation is announced before it starts (:func:`announce_compilation`): numba
fires its ``"numba:compile"`` event (:mod:`numba.core.event`) only when a kernel is not
in the cache, before compiling it, so a listener on that event prints a notice with the
expected duration (:data:`KERNEL_FAMILIES`) the first time each family of kernels
compiles, and nothing when the cache is warm.  ``hertzchain``'s commands run inside it;
so do :class:`discrete.progress.RunProgress` and :func:`hertzchain.reproduce.reproduce`
when they show progress.

Processes that start on the same cold cache (the worker processes of ``hertzchain
reproduce``, a Dask sweep) would each compile the same kernels at the same time, on
the same cores.  A :func:`keyed_njit` kernel therefore compiles under a lock file
beside its cache entry (:func:`compile_lock`): the first process compiles and writes
the cache, the others wait, without using the CPU, and then load what it wrote.

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
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["configure", "default_cache_dir", "cache_is_warm", "KERNEL_FAMILIES",
           "compile_notice", "announce_compilation", "announce", "keyed_njit",
           "source_digest", "compile_lock", "compile_locked", "COMPILE_LOCK_TIMEOUT",
           "compile_cpu_timer"]

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


KERNEL_FAMILIES: dict[str, tuple[str, float]] = {
    "discrete": ("the discrete solver's", 8.0),
    "continuum": ("the continuum solver's", 5.0),
}
"""Kernel families announced when they compile: top-level package → (whose kernels,
expected compile time in s of CPU).

The expected times are those of a cold cache on an idle machine (docs/benchmarks.md):
the discrete solver's kernels of one contact law (its force, energies, active window
and stepping loop), and the continuum's stepping loop of one equation.  Another
contact law, kernel variant or continuum equation compiles again, for about as long."""


def compile_notice(family: str) -> str:
    """The notice printed before ``family``'s kernels compile (:data:`KERNEL_FAMILIES`).

    Parameters
    ----------
    family : str
        A key of :data:`KERNEL_FAMILIES`.

    Returns
    -------
    str
    """
    try:
        what, seconds = KERNEL_FAMILIES[family]
    except KeyError:
        raise ValueError(f"family must be one of {', '.join(map(repr, KERNEL_FAMILIES))} "
                         f"(got {family!r})") from None
    return (f"compiling {what} numba kernels: not in the cache yet (the first run after "
            f"installing or after a change of the code); about {seconds:.0f} s of CPU "
            "time, cached afterwards")


def _family(dispatcher) -> str | None:
    """The :data:`KERNEL_FAMILIES` key of a numba dispatcher's module, or None."""
    py = getattr(dispatcher, "py_func", None)
    module = getattr(py, "__module__", None) or ""
    family = module.split(".", 1)[0]
    return family if family in KERNEL_FAMILIES else None


class _Announcer:
    """Prints :func:`compile_notice` once per family (the ``"numba:compile"`` listener)."""

    def __init__(self, log: Callable[[str], None]) -> None:
        self.log = log
        self.announced: set[str] = set()
        self._lock = threading.Lock()

    def announce(self, family: str) -> bool:
        with self._lock:
            if family in self.announced:
                return False
            self.announced.add(family)
        self.log(compile_notice(family) + " ...")
        return True

    def listener(self):
        from numba.core import event

        announcer = self

        class _Listener(event.Listener):
            def on_start(self, ev) -> None:
                family = _family(ev.data.get("dispatcher"))
                if family is not None:
                    announcer.announce(family)

            def on_end(self, ev) -> None:
                pass

        return _Listener()


@contextmanager
def compile_cpu_timer(add: Callable[[float], None]) -> Iterator[None]:
    """Inside the block, pass the CPU seconds of each numba compilation to ``add``.

    numba's ``"numba:compile"`` events fire only for a real compilation (a cache miss),
    not for a kernel loaded from the disk cache.  The outermost event of a thread is
    timed with that thread's CPU clock (:func:`time.thread_time`: numba compiles in the
    calling thread), so nested compiles (a callee inside its caller) count once and a
    loaded machine's waiting for a core does not count at all, as it would in
    ``numba.core.event.install_timer``'s wall time.
    """
    from numba.core import event

    local = threading.local()

    class _Timer(event.Listener):
        def on_start(self, ev) -> None:
            depth = getattr(local, "depth", 0)
            if depth == 0:
                local.start = time.thread_time()
            local.depth = depth + 1

        def on_end(self, ev) -> None:
            local.depth -= 1
            if local.depth == 0:
                add(time.thread_time() - local.start)

    with event.install_listener("numba:compile", _Timer()):
        yield


_active: list[_Announcer] = []
"""The announcers entered (innermost last); only the outermost listens to numba."""


def _stderr(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


@contextmanager
def announce_compilation(enabled: bool = True,
                         log: Callable[[str], None] | None = None) -> Iterator[None]:
    """Inside the block, announce each family of our kernels before it compiles.

    The first time a kernel of a :data:`KERNEL_FAMILIES` package is compiled (numba's
    ``"numba:compile"`` event, fired after a cache miss and before compiling),
    :func:`compile_notice` is passed to ``log``, once per family and block.  A warm
    cache prints nothing.  Nested blocks share the outermost one's listener and record
    (one notice per family in all); a process forked inside the block inherits both.

    Parameters
    ----------
    enabled : bool
        False: do nothing (an enclosing block still announces).
    log : callable, optional
        Receives each notice (default: print it on stderr).
    """
    if not enabled or _active:
        yield
        return
    from numba.core import event

    announcer = _Announcer(log or _stderr)
    _active.append(announcer)
    try:
        with event.install_listener("numba:compile", announcer.listener()):
            yield
    finally:
        _active.remove(announcer)


def announce(family: str, log: Callable[[str], None] | None = None) -> bool:
    """Announce that ``family``'s kernels are about to compile.

    For a caller that knows, before calling a kernel, that it will compile (a progress
    bar that checked :func:`cache_is_warm`): inside an :func:`announce_compilation`
    block the notice goes through it (once per family: the block then does not
    announce that family again), else to ``log``.

    Parameters
    ----------
    family : str
        A key of :data:`KERNEL_FAMILIES`.
    log : callable, optional
        Receives the notice outside an :func:`announce_compilation` block (default:
        print it on stderr).

    Returns
    -------
    bool
        Whether the notice was printed (False: the block had announced it already).
    """
    notice = compile_notice(family)  # (ValueError for an unknown family)
    if _active:
        return _active[0].announce(family)
    (log or _stderr)(notice + " ...")
    return True


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


COMPILE_LOCK_TIMEOUT = 900.0
"""Longest wait for another process's compilation of the same kernel, s; then compile."""

_lock_depth = threading.local()


@contextmanager
def compile_lock(path: str | os.PathLike, timeout: float = COMPILE_LOCK_TIMEOUT
                 ) -> Iterator[bool]:
    """Hold an exclusive lock on the file ``path`` (created) while compiling a kernel.

    Another process holding it is compiling the same kernel into the same cache: the
    block is entered when it has finished (numba then finds its result in the cache),
    polling every 50 ms without using the CPU.  Only the outermost lock of a thread is
    taken (a kernel compiled while compiling another one is not locked again: two
    processes could otherwise each hold the lock the other waits for).  Where the lock
    cannot be had (no ``fcntl``, an unwritable directory, or after ``timeout`` s) the
    block runs unlocked: the lock saves CPU time, it is not needed for correctness
    (numba writes its cache files atomically).

    Yields
    ------
    bool
        Whether the lock is held.
    """
    depth = getattr(_lock_depth, "n", 0)
    fd = None
    if depth == 0:
        try:
            import fcntl

            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
            deadline = time.monotonic() + timeout
            while True:
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    break
                except BlockingIOError:
                    if time.monotonic() > deadline:
                        os.close(fd)
                        fd = None
                        break
                    time.sleep(0.05)
        except (ImportError, OSError):
            if fd is not None:
                os.close(fd)
            fd = None
    _lock_depth.n = depth + 1
    try:
        yield fd is not None
    finally:
        _lock_depth.n = depth
        if fd is not None:
            os.close(fd)  # (releases the lock)


def _locked_compile(disp, lock_path: str) -> None:
    """Make ``disp`` compile a new signature under :func:`compile_lock` (``lock_path``).

    Taken inside numba's own compiler lock (re-entrant, process-wide), so that threads
    of one process never wait on each other's file locks.
    """
    from numba.core import sigutils
    from numba.core.compiler_lock import global_compiler_lock

    compile_ = disp.compile
    disp.compile_lock_path = lock_path

    def compile(sig):
        args, _ = sigutils.normalize_signature(sig)
        if tuple(args) in disp.overloads:
            return compile_(sig)
        with global_compiler_lock, compile_lock(lock_path):
            return compile_(sig)  # (loads from the cache what a waited-for process wrote)

    disp.compile = compile


def compile_locked(disp):
    """Make a module-level ``numba.njit(cache=True)`` kernel compile under :func:`compile_lock`.

    For a kernel that processes starting on one cold cache call directly (not only
    from inside a :func:`keyed_njit` kernel, whose lock covers what it calls): one
    process compiles it, the others wait and load the cache entry it wrote.  A
    dispatcher without a disk cache is returned unchanged.

    Parameters
    ----------
    disp : numba.core.registry.CPUDispatcher
        The kernel (``numba.njit(cache=True)(...)``).

    Returns
    -------
    numba.core.registry.CPUDispatcher
        ``disp`` itself (usable as a decorator above ``@numba.njit``).
    """
    path = getattr(getattr(disp, "_cache", None), "cache_path", None)
    if path:
        py = disp.py_func
        name = py.__qualname__.replace("<", "").replace(">", "")
        stem = Path(py.__code__.co_filename).stem
        _locked_compile(disp, os.path.join(path, f"{stem}.{name}.lock"))
    return disp


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
    With the cache, a new signature compiles under :func:`compile_lock` on the file
    ``disp.compile_lock_path`` (one process compiles, the others load its result).
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
        else:
            name = py_func.__qualname__.replace("<", "").replace(">", "")
            stem = Path(py_func.__code__.co_filename).stem
            _locked_compile(disp, os.path.join(disp._cache.cache_path,
                                               f"{stem}.{name}.lock"))
    return disp
