"""External programs the project runs (Debian packages, the Makefile's SYSTEM_PACKAGES)."""

from __future__ import annotations

import shutil

from gesturecast.errors import UserError


def installed(program: str, package: str | None = None) -> str:
    """Path of ``program``; UserError naming its Debian package when it is not installed."""
    path = shutil.which(program)
    if path is None:
        raise UserError(f"{program} is not installed (apt-get install {package or program}; see the Makefile's "
                        "SYSTEM_PACKAGES)")
    return path


def espeak() -> str:
    """Path of espeak-ng; UserError when it is not installed."""
    return installed("espeak-ng")
