"""Files kinedyn writes and reads, so that no run loses data and no path blocks forever.

Writing: :func:`replacing` (and :func:`write_text`, :func:`write_bytes` on it) writes into a
temporary file in the destination's folder, flushes it to the disk (``fsync``) and renames it over
the destination (``os.replace``, atomic within one file system, POSIX ``rename(2)``). A run that
fails or is interrupted midway leaves the old file as it was and no half-written one; a reader
never sees a partial file. The destination's permission bits are kept; a new file gets the usual
``0o666`` less the umask. A destination that is a symbolic link is written through it (the link
stays a link); one that is not a regular file (``/dev/null``, a terminal, a pipe) cannot be
replaced and is written in place.

Reading: :func:`open_regular` opens a path only if it is a regular file. A FIFO, a device such as
``/dev/zero`` or a folder is refused with a message naming the path, without blocking: the open
itself does not wait (``O_NONBLOCK``, so opening a FIFO with no writer returns at once), and the
kind of file is taken from the opened descriptor (``fstat``), so it cannot change between the
check and the read.

:func:`same_file` compares two paths by device and inode (``os.path.samefile``): a hard link or a
symbolic link to a file is that file.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import stat
from collections.abc import Iterator
from pathlib import Path

__all__ = ["open_regular", "readable_source", "replacing", "require_regular", "same_file", "write_bytes", "write_text"]


def readable_source(source: str, *, shared: bool = False) -> str:
    """A robot's ``source`` as a page or a table shows it. When it names a file (a robot loaded
    from a path, which keeps the path as typed: ``../x/../robot.urdf`` means nothing once the folder
    it was typed in is gone), the file's resolved path (symbolic links and ``..`` followed), with
    the home folder written ``~``; anything else (a built-in's reference, "URDF string") as it is.
    ``shared``: for a document that leaves the machine (the report), no absolute path: a file under
    the working folder relative to it, under the home folder from ``~``, else ``.../folder/name``."""
    if not source or source.startswith("<") or "\n" in source:
        return source
    try:
        if not os.path.isfile(source):
            return source
        path = os.path.realpath(source)
        home = os.path.realpath(os.path.expanduser("~"))
        here = os.path.realpath(os.getcwd())
    except (OSError, ValueError):  # a name the file system cannot hold (a NUL byte): not a file
        return source
    if shared and here != os.sep and os.path.commonpath([path, here]) == here:
        return os.path.relpath(path, here)
    if home not in ("", os.sep) and os.path.commonpath([path, home]) == home:
        return os.path.join("~", os.path.relpath(path, home))
    if shared:
        folder, name = os.path.split(path)
        return os.path.join("...", os.path.basename(folder), name)
    return path


def same_file(a, b) -> bool:
    """Whether ``a`` and ``b`` name one file (same device and inode), through hard links and
    symbolic links alike; False when either does not exist."""
    try:
        return os.path.samefile(os.fspath(a), os.fspath(b))
    except (OSError, ValueError):
        return False


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISCHR(mode):
        return "a character device"
    if stat.S_ISBLK(mode):
        return "a block device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def require_regular(path, what: str = "file") -> None:
    """ValueError unless ``path`` is a regular file (a symbolic link to one is); the message names
    the path and what it is instead. A missing path raises FileNotFoundError."""
    st = os.stat(os.fspath(path))
    if not stat.S_ISREG(st.st_mode):
        raise ValueError(
            f"{os.fspath(path)}: the {what} is {_kind(st.st_mode)}, not a regular file; kinedyn reads only regular files"
        )


def open_regular(path, what: str = "file", mode: str = "rb", encoding: str | None = None):
    """``open(path, mode)`` for reading, refusing anything but a regular file (ValueError naming
    the path and its kind) before a byte is read, and never blocking on a FIFO or a device."""
    if any(c in mode for c in "wax+"):
        raise ValueError(f"open_regular opens files for reading, not mode '{mode}'")
    fd = os.open(os.fspath(path), os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise ValueError(
                f"{os.fspath(path)}: the {what} is {_kind(st.st_mode)}, not a regular file; kinedyn reads only regular files"
            )
        os.set_blocking(fd, True)
        return os.fdopen(fd, mode, encoding=encoding)
    except BaseException:
        os.close(fd)
        raise


def _target(path: Path) -> Path:
    """Where the bytes go: through symbolic links (the link stays a link and its file is replaced)."""
    return Path(os.path.realpath(path)) if path.is_symlink() else path


@contextlib.contextmanager
def replacing(path) -> Iterator[Path]:
    """A path to write ``path``'s new content to; when the block ends without an exception it is
    flushed to the disk and renamed over ``path`` in one step, and when it raises (or is
    interrupted) it is removed and ``path`` is left untouched. The temporary file lies in the same
    folder, with the same extension (writers that choose a format by the extension choose the same),
    so the rename never crosses file systems."""
    path = Path(os.fspath(path))
    target = _target(path)
    try:
        existing = os.stat(target)
    except FileNotFoundError:
        existing = None
    if existing is not None and not stat.S_ISREG(existing.st_mode):
        yield target  # /dev/null, a terminal, a pipe: there is nothing to replace, the bytes go through
        return
    folder = target.parent
    fd = -1
    while True:
        tmp = folder / f".{target.stem[:80]}.{secrets.token_hex(4)}.tmp{target.suffix}"
        try:
            # 0o666 less the umask for a new file, as open() gives; O_EXCL: never an existing file
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0), 0o666)
            break
        except FileExistsError:
            continue
    os.close(fd)
    try:
        yield tmp
        if existing is not None:
            os.chmod(tmp, stat.S_IMODE(existing.st_mode))
        fd = os.open(tmp, os.O_RDONLY | getattr(os, "O_CLOEXEC", 0))
        try:
            os.fsync(fd)  # the bytes are on the disk before the name points at them
        finally:
            os.close(fd)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    with contextlib.suppress(OSError):  # the rename itself on the disk; some file systems cannot fsync a folder
        dfd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
        try:
            os.fsync(dfd)
        finally:
            os.close(dfd)


def write_bytes(path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically (:func:`replacing`); returns ``Path(path)``."""
    with replacing(path) as tmp, open(tmp, "wb") as f:
        f.write(data)
    return Path(os.fspath(path))


def write_text(path, text: str, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` atomically (:func:`replacing`); returns ``Path(path)``."""
    return write_bytes(path, text.encode(encoding))
