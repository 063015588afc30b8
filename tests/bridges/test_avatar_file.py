"""Which avatar the viewer serves: --avatar, then $GESTURECAST_AVATAR, then the shared default, else none."""

from __future__ import annotations

from pathlib import Path

import pytest

from gesturecast.bridges import avatar_file
from gesturecast.bridges.avatar_file import AVATAR_ENV_VAR, resolve_avatar
from gesturecast.bridges.viewer_http import static_response
from gesturecast.errors import UserError

GLB_START = b"glTF\x02\x00\x00\x00"


@pytest.fixture
def vrm(tmp_path) -> Path:
    path = tmp_path / "mine.vrm"
    path.write_bytes(GLB_START + b"rest of the file")
    return path


@pytest.fixture
def no_default(tmp_path, monkeypatch):
    """Neither the repository root nor the working folder has ../shared/assets/cryptovoxels.vrm."""
    monkeypatch.setattr(avatar_file, "REPOSITORY_ROOT", tmp_path / "repo")
    monkeypatch.chdir(tmp_path)


def test_the_flag_wins_over_the_environment(vrm, tmp_path):
    assert resolve_avatar(vrm, {AVATAR_ENV_VAR: str(tmp_path / "other.vrm")}) == vrm


def test_the_environment_names_the_avatar(vrm, no_default):
    assert resolve_avatar(None, {AVATAR_ENV_VAR: str(vrm)}) == vrm


def test_the_default_is_found_next_to_the_working_folder(vrm, tmp_path, no_default, monkeypatch):
    checkout = tmp_path / "work" / "checkout"
    checkout.mkdir(parents=True)
    (tmp_path / "work" / "shared" / "assets").mkdir(parents=True)
    default = tmp_path / "work" / "shared" / "assets" / "cryptovoxels.vrm"
    default.write_bytes(vrm.read_bytes())
    monkeypatch.chdir(checkout)
    assert resolve_avatar(None, {}) == default.resolve()


def test_no_avatar_anywhere_is_none(no_default):
    assert resolve_avatar(None, {}) is None


@pytest.mark.parametrize("content, message", [(None, "cannot read"), (b"PK\x03\x04zip", "not a VRM file")])
def test_an_unusable_choice_is_one_line_naming_it(tmp_path, content, message):
    path = tmp_path / "bad.vrm"
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(UserError, match=f"--avatar: .*{message}"):
        resolve_avatar(path, {})
    with pytest.raises(UserError, match=f"{AVATAR_ENV_VAR}: .*{message}"):
        resolve_avatar(None, {AVATAR_ENV_VAR: str(path)})


def test_the_page_gets_the_avatar_and_the_bundled_libraries(vrm):
    served = static_response("/avatar.vrm?x=1", vrm)
    assert served.status_code == 200 and served.body == vrm.read_bytes()
    assert served.headers["Content-Type"] == "model/gltf-binary"
    assert static_response("/avatar.vrm", None).status_code == 404
    bundle = static_response("/vendor/three-vrm.bundle.js")
    assert bundle.status_code == 200 and b"VRMLoaderPlugin" in bundle.body
    assert b"MIT License" in static_response("/vendor/three-vrm.LICENSE").body
