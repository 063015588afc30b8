"""Output files that are never half-written and never clobber something they should not.

Every command that writes a file goes through :func:`atomic_path` (or :func:`atomic_file` /
:func:`write_text_atomic` on top of it): the content goes to a temporary file in the target's
folder, is flushed to disk (``fsync``), then renamed over the target in one step. So:

- a failure (disk full, read-only folder, file size limit) leaves the old target untouched, removes
  the temporary file and reaches the user as one :class:`UserError` line;
- an existing target that is not a regular file (a FIFO, a device node, a folder) is refused before
  anything is written; a symbolic link is followed, so the file it points to is replaced;
- new files get the usual mode from the umask (0644 under umask 022), not ``mkstemp``'s 0600.

:func:`check_distinct` refuses an output that is also an input or another output (the same file
through any path or link), before anything is opened.
"""

from __future__ import annotations

import errno
import os
import secrets
import stat
import sys
from collections.abc import Iterator, Sequence
from contextlib import ExitStack, contextmanager, suppress
from pathlib import Path
from typing import IO

from gesturecast.errors import UserError

NEW_FILE_MODE = 0o666  # before the umask, as open() creates files
TEMP_NAME_BYTES = 4  # random bytes in a temporary file's name
TEMP_NAME_TRIES = 100  # a name collision this often means something else is wrong


def check_output_target(path: str | Path) -> Path:
    """The path to replace (symlinks resolved); refuses an existing target that is not a regular file."""
    target = Path(os.path.realpath(path))
    try:
        mode = target.stat().st_mode
    except FileNotFoundError:
        return target
    except OSError as error:
        raise UserError(f"cannot write {path}: {error.strerror}") from None
    if stat.S_ISDIR(mode):
        raise UserError(f"cannot write {path}: it is a folder, not a file")
    if not stat.S_ISREG(mode):
        raise UserError(f"refusing to replace {path}: it exists and is not a regular file (a FIFO, device or socket)")
    return target


def _create_temp(target: Path) -> Path:
    """An empty new file next to ``target``, created with the umask's mode."""
    for _ in range(TEMP_NAME_TRIES):
        temp = target.with_name(f".{target.name}.{secrets.token_hex(TEMP_NAME_BYTES)}.tmp")
        try:
            os.close(os.open(temp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, NEW_FILE_MODE))
        except FileExistsError:
            continue
        return temp
    raise FileExistsError(errno.EEXIST, "no free temporary file name", str(target.parent))


def _fsync(path: Path) -> None:
    # Windows flushes only a handle opened for writing (a read-only one fails with EBADF)
    fd = os.open(path, os.O_RDWR if sys.platform == "win32" else os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path to fill (by any writer, even another process); on success it replaces ``path``.

    An ``OSError`` while writing or renaming becomes one ``UserError`` line; on any exception the
    temporary file is removed and ``path`` is left as it was.
    """
    target = check_output_target(path)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        temp = _create_temp(target)
    except OSError as error:
        raise UserError(f"cannot write {path}: {error.strerror}") from None
    try:
        yield temp
        _fsync(temp)
        os.replace(temp, target)
    except OSError as error:
        temp.unlink(missing_ok=True)
        raise UserError(f"cannot write {path}: {error.strerror or error}") from None
    except BaseException:
        temp.unlink(missing_ok=True)
        raise


@contextmanager
def atomic_file(path: str | Path, binary: bool = False) -> Iterator[IO]:
    """An open file (text UTF-8 with ``\\n`` line ends, or binary) whose content replaces ``path`` on success."""
    with atomic_path(path) as temp:
        handle = temp.open("wb") if binary else temp.open("w", encoding="utf-8", newline="\n")
        try:
            yield handle
        except BaseException:
            with suppress(OSError):  # the content is dropped: a failing flush changes nothing
                handle.close()
            raise
        handle.close()


class Abandoned(Exception):
    """Thrown into an unfinished :func:`atomic_file` to drop it: the target stays as it was."""


def abandon(files: ExitStack) -> None:
    """Close the :func:`atomic_file` s entered on ``files`` without replacing their targets."""
    files.__exit__(Abandoned, Abandoned(), None)


def write_text_atomic(path: str | Path, text: str) -> None:
    """Replace ``path`` by ``text`` atomically (see :func:`atomic_path`)."""
    with atomic_file(path) as handle:
        handle.write(text)


def save_figure(figure: object, path: str | Path, dpi: int) -> Path:
    """Save a matplotlib figure atomically; the format follows the suffix (``.png``, ``.svg``, ``.pdf``)."""
    with atomic_file(path, binary=True) as handle:
        figure.savefig(handle, format=Path(path).suffix.lstrip(".").lower(), dpi=dpi)
    return Path(path)


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.samefile(b)
    except OSError:  # one of them does not exist yet: compare where they would be
        return os.path.realpath(a) == os.path.realpath(b)


def check_distinct(inputs: Sequence[tuple[str, str | Path | None]], outputs: Sequence[tuple[str, str | Path | None]]
                   ) -> None:
    """Refuse an output that is an input or another output (same file by any path or link).

    Each entry is ``(flag, path)``; entries whose path is None are not used.
    """
    named = [(flag, Path(p)) for flag, p in (*inputs, *outputs) if p is not None]
    first_output = len([p for _, p in inputs if p is not None])
    for i in range(first_output, len(named)):
        flag, path = named[i]
        for other_flag, other in named[:i]:
            if _same_file(path, other):
                raise UserError(f"{flag} {path} is the same file as {other_flag} {other}: "
                                f"it would be overwritten; choose another output file")
