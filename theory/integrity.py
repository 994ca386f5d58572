"""Integrity of every file hertzchain writes and reads back: a SHA-256 seal, checked on read.

One mechanism, two carriers:

* **Binary files** (HDF5 results, checkpoints, caches, sweep tables; the ``.npz``
  settled-wave cache; py-pde ``FileStorage`` outputs) start with a 512-byte header,
  :data:`HEADER_SIZE`, that holds the SHA-256 digest and the length of everything after
  it.  For HDF5 the header *is* the file's user block, which the HDF5 library skips: a
  sealed file stays an ordinary HDF5 file for h5py, ``h5dump`` or py-pde.  Every byte
  is covered — datasets of any size, every attribute, the HDF5 metadata, unused space,
  and the header itself (it is rebuilt from its fields and compared byte for byte) — so
  any change of any bit is found on read: a changed parameter, attribute or value, a
  truncated or extended file.
* **JSON text** (the lines of a sweep's ``records.jsonl``, ``spec.json``) carries the
  digest of its own exact bytes as a last member ``"sha256"``: each line of an
  append-only log is checked on its own, and a bad byte is reported with its line.

Writers are atomic: the content goes to a temporary file in the target directory
(named ``.<name>.<pid>-<random>.tmp``, so a process can tell its own temporaries and
those of a dead process from another live writer's), which is sealed, flushed to disk
(``fsync``), given the permissions of a normally created file (``0o666 & ~umask``) and
renamed onto the target; the directory is then flushed too.  A crash leaves the old
file or the new one, never a part.

Readers call :func:`verify` (or :func:`open_hdf5`, :func:`read_sealed_bytes`,
:func:`loads_sealed_json`) and get an :class:`IntegrityError` (a ``ValueError``) that
names the file and what is wrong.  A file without a seal (written by another program or
an older hertzchain) is refused the same way: its content cannot be vouched for.

Why here: :mod:`discrete`, :mod:`continuum` and :mod:`hertzchain` all write files, and
:mod:`theory` is the one package every one of them may import (``discrete`` and
``continuum`` import nothing else of ours); the module uses only the standard library
and imports h5py only when an HDF5 file is written, so it adds no dependency to
:mod:`theory` (the same reason :mod:`theory.jitcache` lives here).

Cost: SHA-256 runs at ~1-2 GB/s (``hashlib``/OpenSSL); a writer reads its file back
once from the page cache, a reader once before opening it.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import os
import re
import tempfile
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import IO, Any

__all__ = ["HEADER_SIZE", "SCHEME", "IntegrityError", "atomic_path", "write_error", "sealed_hdf5",
           "sealed_binary", "write_sealed_bytes", "seal_file", "verify", "is_sealed",
           "open_hdf5", "read_sealed_bytes", "dumps_sealed_json", "loads_sealed_json",
           "temporary_pattern", "umask"]

SCHEME = "hertzchain-sealed/1"
"""First line of the header of a sealed binary file."""
HEADER_SIZE = 512
"""Bytes of the header (the smallest HDF5 user block)."""
_CHUNK = 1 << 22


class IntegrityError(ValueError):
    """A file fails its integrity check: missing seal, changed, truncated or extended."""


# -- small helpers ------------------------------------------------------------------------
def umask() -> int:
    """The process umask, read without changing it where possible (threads)."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0)
    os.umask(mask)
    return mask


def temporary_pattern(path: str | os.PathLike) -> str:
    """Glob pattern of the temporaries of ``path`` (``.<name>.*.tmp``, escaped)."""
    import glob

    return f".{glob.escape(Path(path).name)}.*.tmp"


def _fsync_dir(directory: Path) -> None:
    with contextlib.suppress(OSError):  # not every file system lets a directory be fsynced
        fd = os.open(directory, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, *,
                finish: Callable[[Path], None] | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; publish it onto ``path`` on success.

    The temporary is ``.<name>.<pid>-<random>.tmp`` in the target directory.  On
    success ``finish(tmp)`` runs (e.g. sealing), the file is flushed to disk, given the
    permissions of a normally created file and renamed onto ``path``.  On an exception
    the temporary is removed and ``path`` is left untouched.
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, name = tempfile.mkstemp(prefix=f".{path.name}.{os.getpid()}-", suffix=".tmp",
                                    dir=path.parent)
    except OSError as exc:
        raise write_error(exc, path) from None
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        if finish is not None:
            finish(tmp)
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.chmod(tmp, 0o666 & ~umask())  # mkstemp creates 0600; a result is shared
        os.replace(tmp, path)
    except OSError as exc:
        raise write_error(exc, path) from None
    finally:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
    _fsync_dir(path.parent)


def write_error(exc: OSError, path: str | os.PathLike) -> OSError:
    """``exc`` naming the file being written; a full disk says so ("disk full ... PATH").

    The one wording of a failed write, used by :func:`atomic_path` and by callers that
    catch a writer's error (``hertzchain.checkpoint.OutputWriteError``).
    """
    if exc.errno == errno.ENOSPC:
        return OSError(errno.ENOSPC, "disk full (no space left on device) writing", str(path))
    if exc.errno is not None and exc.filename is None:
        return type(exc)(exc.errno, f"{exc.strerror or exc} writing", str(path))
    return exc



# -- binary files: a 512-byte header with the digest of the rest ------------------------
def _header(digest: str, size: int) -> bytes:
    text = (f"{SCHEME}\nsha256 {digest}\nbytes {size}\n"
            "The rest of this file is covered by the SHA-256 digest above "
            "(hertzchain: theory/integrity.py).\n").encode("ascii")
    return text + b" " * (HEADER_SIZE - 1 - len(text)) + b"\n"


def _hash_from(fh: IO[bytes], offset: int) -> tuple[str, int]:
    fh.seek(offset)
    h, n = hashlib.sha256(), 0
    while chunk := fh.read(_CHUNK):
        h.update(chunk)
        n += len(chunk)
    return h.hexdigest(), n


def _write_header(path: Path) -> None:
    """Seal a file whose first :data:`HEADER_SIZE` bytes are reserved (in place)."""
    with open(path, "r+b") as fh:
        digest, size = _hash_from(fh, HEADER_SIZE)
        fh.seek(0)
        fh.write(_header(digest, size))


@contextlib.contextmanager
def sealed_hdf5(path: str | os.PathLike, *, in_memory: bool = False,
                **kwargs) -> Iterator[Any]:
    """Write a sealed HDF5 file atomically: yields an ``h5py.File`` opened for writing.

    The file gets a :data:`HEADER_SIZE`-byte user block that receives the seal once the
    file is closed; ``kwargs`` go to ``h5py.File``.  ``in_memory``: the file is built in
    memory and written to disk with one plain write, so a full disk is a clean
    ``OSError`` (HDF5 failing inside h5py's destructors can crash the interpreter);
    for small files (sweep tables).
    """
    import h5py

    if in_memory:
        import io

        buf = io.BytesIO()
        f = h5py.File(buf, "w", userblock_size=HEADER_SIZE, **kwargs)
        try:
            yield f
        finally:
            f.close()  # in memory: nothing to fail for lack of space
        with atomic_path(path, finish=_write_header) as tmp, open(tmp, "wb") as fh:
            fh.write(buf.getbuffer())
        return

    with atomic_path(path, finish=_write_header) as tmp:
        f = h5py.File(tmp, "w", userblock_size=HEADER_SIZE, **kwargs)
        try:
            yield f
        except BaseException as exc:
            _abandon(f, tmp)
            io = _as_os_error(exc)
            if io is not None:
                raise io from None
            raise
        try:
            f.close()  # never twice: a second close of a failed one crashes HDF5
        except (RuntimeError, ValueError) as exc:
            io = _as_os_error(exc)
            if io is not None:
                raise io from None
            raise


_HDF5_ERRNO = re.compile(r"errno = (\d+), error message = '([^']*)'")


def _as_os_error(exc: BaseException) -> OSError | None:
    """An HDF5 I/O failure that h5py raised as another type, as an OSError.

    E.g. ``RuntimeError: Can't decrement id ref count (file write failed: ... errno =
    28 ...)`` on a full disk; :func:`atomic_path` then names the file.
    """
    if isinstance(exc, OSError) or not isinstance(exc, RuntimeError | ValueError):
        return None
    m = _HDF5_ERRNO.search(str(exc))
    return OSError(int(m.group(1)), m.group(2)) if m else None



def _abandon(f, tmp: Path) -> None:
    """Close a half-written HDF5 file that is about to be deleted, whatever its state.

    After a failed write (a full disk) HDF5's close flushes again and fails; the file
    then stays open in the library and is flushed once more when Python frees its
    objects — after :func:`atomic_path` deleted it: a flood of "Exception ignored" and a
    segmentation fault.  The file's descriptor is pointed at ``os.devnull`` first, so the
    closing flush succeeds and writes nowhere (the content is discarded anyway); where
    the driver has no descriptor, truncating the temporary frees its blocks instead.
    """
    try:
        fd = f.id.get_vfd_handle()
    except Exception:  # noqa: BLE001 - another driver, or already closed
        fd = None
    if isinstance(fd, int) and fd >= 0:
        null = os.open(os.devnull, os.O_WRONLY)
        try:
            os.dup2(null, fd)
        finally:
            os.close(null)
    else:
        with contextlib.suppress(OSError):
            os.truncate(tmp, 0)
    with contextlib.suppress(Exception):
        f.close()


@contextlib.contextmanager
def sealed_binary(path: str | os.PathLike) -> Iterator[IO[bytes]]:
    """Write a sealed binary file atomically: yields a file object for the content."""
    with atomic_path(path, finish=_write_header) as tmp, open(tmp, "wb") as fh:
        fh.write(b"\0" * HEADER_SIZE)
        yield fh


def write_sealed_bytes(path: str | os.PathLike, payload: bytes) -> Path:
    """Write ``payload`` to ``path`` sealed and atomically; returns ``path``."""
    with sealed_binary(path) as fh:
        fh.write(payload)
    return Path(path)


def seal_file(path: str | os.PathLike, target: str | os.PathLike | None = None) -> Path:
    """Seal a finished, unsealed file written by someone else (e.g. py-pde).

    Its content is copied after a new header into ``target`` (default: ``path``
    itself), atomically; HDF5 finds its superblock after the header (a user block) and
    reads the file as before.  Returns the sealed file.
    """
    path = Path(path)
    target = path if target is None else Path(target)
    with sealed_binary(target) as out, open(path, "rb") as src:
        while chunk := src.read(_CHUNK):
            out.write(chunk)
    return target


def is_sealed(path: str | os.PathLike) -> bool:
    """True if ``path`` starts with a seal header (whether or not the content matches)."""
    try:
        with open(path, "rb") as fh:
            return fh.read(len(SCHEME) + 1) == f"{SCHEME}\n".encode()
    except OSError:
        return False


_HEADER_RE = re.compile(rb"([^\n]*)\nsha256 ([0-9a-f]{64})\nbytes ([0-9]{1,20})\n")


def verify(path: str | os.PathLike, *, what: str = "file") -> None:
    """Check the seal of a binary file; :class:`IntegrityError` naming ``path`` if it fails.

    ``what`` names the kind of file in the message ("result file", "checkpoint", ...).
    """
    path = Path(path)
    if not path.is_file():
        raise IntegrityError(f"{path}: no such file")
    with open(path, "rb") as fh:
        head = fh.read(HEADER_SIZE)
        m = _HEADER_RE.match(head)
        if len(head) < HEADER_SIZE or m is None or m.group(1) != SCHEME.encode():
            if head.startswith(SCHEME.encode()):
                raise IntegrityError(f"{path}: damaged {what}: its integrity header is "
                                     "corrupted")
            raise IntegrityError(
                f"{path}: no integrity seal, so its content cannot be verified: not a "
                f"hertzchain {what} (or one written by an older version, or truncated)")
        digest, size = m.group(2).decode(), int(m.group(3))
        if head != _header(digest, size):
            raise IntegrityError(f"{path}: damaged {what}: its integrity header is "
                                 "corrupted")
        found, n = _hash_from(fh, HEADER_SIZE)
    if n != size:
        raise IntegrityError(f"{path}: damaged {what}: {n} bytes of content where the seal "
                             f"says {size} ({'truncated' if n < size else 'extended'})")
    if found != digest:
        raise IntegrityError(f"{path}: damaged {what}: the content does not match its "
                             "SHA-256 seal (changed on disk since it was written)")


@contextlib.contextmanager
def open_hdf5(path: str | os.PathLike, *, what: str = "file") -> Iterator[Any]:
    """Verify a sealed HDF5 file, then yield it opened read-only (``h5py.File``).

    Raises :class:`IntegrityError` if the seal fails, or if the verified file is not
    a readable HDF5 file (it was sealed so, e.g. by a writer of another format).
    """
    import h5py

    verify(path, what=what)
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise IntegrityError(f"{path}: {what} is not a readable HDF5 file: {exc}") from None
    with f:
        yield f


def read_sealed_bytes(path: str | os.PathLike, *, what: str = "file") -> bytes:
    """The verified content of a sealed binary file (without the header)."""
    verify(path, what=what)
    with open(path, "rb") as fh:
        fh.seek(HEADER_SIZE)
        return fh.read()


# -- JSON text: the digest of the exact bytes as a last member --------------------------
_JSON_RE = re.compile(r'(\{.*),"sha256":"([0-9a-f]{64})"\}')


def dumps_sealed_json(obj: Mapping, *, default: Callable | None = None) -> str:
    """One-line JSON of ``obj`` (sorted keys) with a last member ``"sha256"``.

    The digest covers the exact text of the object without that member, so a change of
    any byte of the line is found by :func:`loads_sealed_json`.
    """
    if "sha256" in obj:
        raise ValueError("the key 'sha256' is reserved for the digest")
    body = json.dumps(obj, sort_keys=True, separators=(",", ":"), default=default)
    if not body.startswith("{") or body == "{}":
        raise ValueError("only a non-empty JSON object can be sealed")
    digest = hashlib.sha256(body.encode()).hexdigest()
    return f'{body[:-1]},"sha256":"{digest}"}}'


def loads_sealed_json(text: str, *, where: str) -> dict:
    """Parse a line written by :func:`dumps_sealed_json`, checking its digest.

    ``where`` names the text in the error ("records.jsonl line 3").
    """
    m = _JSON_RE.fullmatch(text.rstrip("\n"))
    if m is None:
        raise IntegrityError(f"{where}: damaged (no integrity digest at the end of the "
                             "line; not written by this version of hertzchain?)")
    body = m.group(1) + "}"
    if hashlib.sha256(body.encode()).hexdigest() != m.group(2):
        raise IntegrityError(f"{where}: damaged (the text does not match its SHA-256 "
                             "digest)")
    try:
        obj = json.loads(body)
    except ValueError as exc:  # pragma: no cover - a matching digest means it was valid
        raise IntegrityError(f"{where}: damaged (not JSON: {exc})") from None
    if not isinstance(obj, dict):  # pragma: no cover
        raise IntegrityError(f"{where}: damaged (not a JSON object)")
    return obj
