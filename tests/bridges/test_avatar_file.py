"""Which avatar the viewer serves: --avatar, then $GESTURECAST_AVATAR, then the packaged one (none if it is missing)."""

from __future__ import annotations

import urllib.request
from pathlib import Path

import pytest

from gesturecast.bridges import avatar_file
from gesturecast.bridges.avatar_file import AVATAR_ENV_VAR, PACKAGED_AVATAR, PACKAGED_AVATAR_LICENSE, resolve_avatar
from gesturecast.bridges.viewer_http import static_response
from gesturecast.bridges.websocket_server import WebSocketBridge, WebSocketConfig
from gesturecast.errors import UserError

GLB_START = b"glTF\x02\x00\x00\x00"
TIMEOUT_S = 10.0


def served_avatar(avatar: Path | None, path: str = "/avatar.vrm") -> tuple[int, bytes, str]:
    """(status, body, content type) of ``path`` from a viewer bridge serving ``avatar``."""
    bridge = WebSocketBridge(WebSocketConfig(port=0, avatar=avatar)).start()
    try:
        with urllib.request.urlopen(f"http://127.0.0.1:{bridge.port}{path}", timeout=TIMEOUT_S) as response:
            return response.status, response.read(), response.headers["Content-Type"]
    except urllib.error.HTTPError as error:
        return error.code, error.read(), error.headers["Content-Type"]
    finally:
        bridge.close()


@pytest.fixture
def vrm(tmp_path) -> Path:
    path = tmp_path / "mine.vrm"
    path.write_bytes(GLB_START + b"rest of the file")
    return path


@pytest.fixture
def elsewhere(tmp_path, monkeypatch):
    """The working folder is a fresh one, with no ../shared next to it."""
    work = tmp_path / "elsewhere"
    work.mkdir()
    monkeypatch.chdir(work)
    monkeypatch.delenv(AVATAR_ENV_VAR, raising=False)
    assert not (work.parent / "shared").exists()


def test_the_flag_wins_over_the_environment(vrm, tmp_path):
    assert resolve_avatar(vrm, {AVATAR_ENV_VAR: str(tmp_path / "other.vrm")}) == vrm


def test_the_environment_names_the_avatar(vrm, elsewhere):
    assert resolve_avatar(None, {AVATAR_ENV_VAR: str(vrm)}) == vrm


def test_without_a_choice_the_packaged_avatar_is_served_from_inside_the_package(elsewhere):
    """No flag, no environment variable, no ../shared: the avatar shipped in the package, a glTF binary (VRM)
    with its licence note beside it."""
    found = resolve_avatar(None)
    package_folder = Path(avatar_file.__file__).resolve().parent
    assert found == PACKAGED_AVATAR and found.resolve().is_relative_to(package_folder)
    header = found.read_bytes()[:12]
    assert header[:4] == b"glTF" and int.from_bytes(header[4:8], "little") == 2
    assert int.from_bytes(header[8:12], "little") == found.stat().st_size  # the whole file, not a stub
    note = PACKAGED_AVATAR_LICENSE.read_text(encoding="utf-8")
    assert PACKAGED_AVATAR_LICENSE.parent == found.parent
    assert '"jin"' in note and "redistribution allowed" in note and "madjin/vrm-samples" in note
    status, body, _ = served_avatar(found)
    assert status == 200 and body == found.read_bytes()


def test_a_missing_packaged_avatar_is_none(elsewhere, tmp_path, monkeypatch):
    monkeypatch.setattr(avatar_file, "PACKAGED_AVATAR", tmp_path / "gone" / "cryptovoxels.vrm")
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
    assert served_avatar(vrm, "/avatar.vrm?x=1") == (200, vrm.read_bytes(), "model/gltf-binary")
    assert served_avatar(None)[0] == 404
    bundle = static_response("/vendor/three-vrm.bundle.js")
    assert bundle.status_code == 200 and b"VRMLoaderPlugin" in bundle.body
    assert b"MIT License" in static_response("/vendor/three-vrm.LICENSE").body
