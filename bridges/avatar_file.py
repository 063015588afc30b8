"""Which VRM avatar the browser viewer shows: ``--avatar PATH``, else ``$GESTURECAST_AVATAR``, else the
packaged default, ``viewer/avatar/cryptovoxels.vrm`` inside this package (a VRM 0.x avatar by "jin" whose
licence allows redistribution: ``viewer/avatar/cryptovoxels.LICENSE`` beside it). Only when that file is
missing (a broken install) is there none: the page then shows the stick figure and "drop a .vrm here".

The chosen file is read from its path when the page asks for it.
"""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path

from gesturecast.bridges.gltf_binary import GLB_MAGIC
from gesturecast.errors import UserError

AVATAR_ENV_VAR = "GESTURECAST_AVATAR"
# the package's own folder on disk (a wheel is installed unzipped, an editable install points at bridges/)
PACKAGED_AVATAR = Path(str(resources.files("gesturecast.bridges"))) / "viewer" / "avatar" / "cryptovoxels.vrm"
PACKAGED_AVATAR_LICENSE = PACKAGED_AVATAR.with_suffix(".LICENSE")


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
    if PACKAGED_AVATAR.is_file():
        return checked_avatar(PACKAGED_AVATAR, "the packaged avatar")
    return None
