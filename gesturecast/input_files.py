"""Reading a user-given input file whole, with a size bound.

A path a user gives may name a device (``/dev/zero`` never ends), a FIFO or a file far larger than what it
should hold; ``Path.read_text()`` would read all of it (a ``--token-file /dev/zero`` read 4.4 GB). Every such
read goes through :func:`read_bounded`: it reads at most ``limit + 1`` bytes and refuses a file that has
more, so the cost is bounded by the limit whatever the path names.

The limits live beside their readers: a token file (``bridges/ws_access.py``), a joint map
(``models/motion/joint_maps.py``), a BVH file (``models/motion/motion.py``), a model manifest
(``models/runtime/bundle.py``) and a batch CSV (``realtime/jobs/batch_jobs.py``).
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from gesturecast.errors import UserError

KIB = 1 << 10
MIB = 1 << 20


def format_size(num_bytes: int) -> str:
    """A byte count as people read it: ``4 KiB``, ``64 MiB``, ``1024 MiB``, ``100 bytes``."""
    if num_bytes >= MIB and num_bytes % MIB == 0:
        return f"{num_bytes // MIB} MiB"
    if num_bytes >= KIB and num_bytes % KIB == 0:
        return f"{num_bytes // KIB} KiB"
    return f"{num_bytes} bytes"


def read_bounded(path: str | Path, limit: int, what: str, regular_only: bool = False) -> bytes:
    """The whole content of ``path`` when it holds at most ``limit`` bytes, reading at most ``limit + 1``.

    ``what`` names the file in the one-line UserError for a file that cannot be opened (missing, a folder,
    no permission) or that holds more than ``limit`` bytes (also a device such as ``/dev/zero``). With
    ``regular_only`` anything but a regular file (a FIFO, which would wait for a writer; a device) is refused
    without waiting: it is opened non-blocking and looked at before any read.
    """
    flags = os.O_RDONLY | (os.O_NONBLOCK if regular_only and hasattr(os, "O_NONBLOCK") else 0)
    try:
        descriptor = os.open(path, flags)
        with open(descriptor, "rb") as handle:
            if regular_only and not stat.S_ISREG(os.fstat(descriptor).st_mode):
                raise UserError(f"{what} {path} is not a regular file (a FIFO, device or folder)")
            data = handle.read(limit + 1)
    except OSError as error:
        raise UserError(f"cannot read {what} {path}: {error.strerror or error}") from None
    if len(data) > limit:
        raise UserError(f"{what} {path} holds more than {format_size(limit)}, the most it may hold")
    return data
