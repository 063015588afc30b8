"""Plain HTTP GET on the WebSocket port: serves the browser viewer page (bridges/viewer/) and its avatar.

``/avatar.vrm`` is the file chosen by :func:`gesturecast.bridges.avatar_file.resolve_avatar`, read from
disk on each request (404 when there is none: the page then shows the stick figure).
"""

from __future__ import annotations

from http import HTTPStatus
from importlib import resources
from pathlib import Path

from websockets.datastructures import Headers
from websockets.http11 import Request, Response

JAVASCRIPT = "text/javascript; charset=utf-8"
TEXT = "text/plain; charset=utf-8"
VIEWER_FILES: dict[str, tuple[str, str]] = {
    "/": ("index.html", "text/html; charset=utf-8"),
    "/index.html": ("index.html", "text/html; charset=utf-8"),
    "/viewer.js": ("viewer.js", JAVASCRIPT),
    "/stick.js": ("stick.js", JAVASCRIPT),
    "/avatar.js": ("avatar.js", JAVASCRIPT),
    "/mouth.js": ("mouth.js", JAVASCRIPT),
    "/viewer.css": ("viewer.css", "text/css; charset=utf-8"),
    "/vendor/three-vrm.bundle.js": ("vendor/three-vrm.bundle.js", JAVASCRIPT),
    "/vendor/three.LICENSE": ("vendor/three.LICENSE", TEXT),
    "/vendor/three-vrm.LICENSE": ("vendor/three-vrm.LICENSE", TEXT),
    "/vendor/three-vrm-animation.LICENSE": ("vendor/three-vrm-animation.LICENSE", TEXT),
}
AVATAR_PATH = "/avatar.vrm"
AVATAR_TYPE = "model/gltf-binary"


def is_websocket_upgrade(request: Request) -> bool:
    return "websocket" in request.headers.get("Upgrade", "").lower()


def viewer_file(name: str) -> bytes:
    return (resources.files("gesturecast.bridges") / "viewer").joinpath(*name.split("/")).read_bytes()


def _found(path: str, avatar: Path | None) -> tuple[bytes, str] | None:
    """(body, content type) for ``path``, or None."""
    if path == AVATAR_PATH:
        try:
            return (avatar.read_bytes(), AVATAR_TYPE) if avatar is not None else None
        except OSError:
            return None
    entry = VIEWER_FILES.get(path)
    return None if entry is None else (viewer_file(entry[0]), entry[1])


def static_response(path: str, avatar: Path | None = None) -> Response:
    """200 with the viewer file (or the avatar) for ``path`` (query string ignored), else 404."""
    found = _found(path.split("?", 1)[0], avatar)
    if found is None:
        status, (body, content_type) = HTTPStatus.NOT_FOUND, (b"not found\n", TEXT)
    else:
        status, (body, content_type) = HTTPStatus.OK, found
    headers = Headers(
        [("Content-Type", content_type), ("Content-Length", str(len(body))), ("Cache-Control", "no-store"),
         ("Connection", "close")]
    )
    return Response(status.value, status.phrase, headers, body)
