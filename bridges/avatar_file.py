"""Which VRM avatar the browser viewer shows: ``--avatar PATH``, else ``$GESTURECAST_AVATAR``, else the
shared default ``../shared/assets/cryptovoxels.vrm`` next to the checkout (looked up from the repository
root, then from the working folder), else none (the page shows the stick figure and "drop a .vrm here").

The avatar is never part of the package: it is read from its path when the page asks for it.
"""

from __future__ import annotations

import os
from pathlib import Path

from gesturecast.bridges.gltf_binary import GLB_MAGIC
from gesturecast.errors import UserError

AVATAR_ENV_VAR = "GESTURECAST_AVATAR"
DEFAULT_AVATAR = Path("..") / "shared" / "assets" / "cryptovoxels.vrm"
REPOSITORY_ROOT = Path(__file__).resolve().parents[1]  # bridges/ lies at the repository root


def checked_avatar(path: Path, source: str) -> Path:
    """``path`` when it is a readable glTF binary (a VRM file is one); UserError naming ``source`` otherwise."""
    try:
        with path.open("rb") as handle:
            magic = handle.read(len(GLB_MAGIC))
    except OSError as error:
        raise UserError(f"{source}: cannot read the avatar {path}: {error.strerror}") from None
    if magic != GLB_MAGIC:
        raise UserError(f"{source}: {path} is not a VRM file (a VRM is a glTF binary starting with 'glTF')")
    return path


def resolve_avatar(flag: str | Path | None, environ: dict[str, str] | None = None) -> Path | None:
    """The avatar file to serve (see the module docstring); an explicit choice that is unusable is an error."""
    environ = os.environ if environ is None else environ
    if flag is not None:
        return checked_avatar(Path(flag), "--avatar")
    if environ.get(AVATAR_ENV_VAR):
        return checked_avatar(Path(environ[AVATAR_ENV_VAR]), AVATAR_ENV_VAR)
    for base in (REPOSITORY_ROOT, Path.cwd()):
        if (base / DEFAULT_AVATAR).is_file():
            return checked_avatar((base / DEFAULT_AVATAR).resolve(), "the default avatar")
    return None
