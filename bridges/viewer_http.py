"""Plain HTTP GET on the WebSocket port: serves the browser viewer page (bridges/viewer/)."""

from __future__ import annotations

from http import HTTPStatus
from importlib import resources

from websockets.datastructures import Headers
from websockets.http11 import Request, Response

VIEWER_FILES: dict[str, tuple[str, str]] = {
    "/": ("index.html", "text/html; charset=utf-8"),
    "/index.html": ("index.html", "text/html; charset=utf-8"),
    "/viewer.js": ("viewer.js", "text/javascript; charset=utf-8"),
    "/viewer.css": ("viewer.css", "text/css; charset=utf-8"),
}


def is_websocket_upgrade(request: Request) -> bool:
    return "websocket" in request.headers.get("Upgrade", "").lower()


def viewer_file(name: str) -> bytes:
    return (resources.files("gesturecast.bridges") / "viewer" / name).read_bytes()


def static_response(path: str) -> Response:
    """200 with the viewer file for ``path`` (query string ignored), else 404."""
    entry = VIEWER_FILES.get(path.split("?", 1)[0])
    if entry is None:
        status, body, content_type = HTTPStatus.NOT_FOUND, b"not found\n", "text/plain; charset=utf-8"
    else:
        status, body, content_type = HTTPStatus.OK, viewer_file(entry[0]), entry[1]
    headers = Headers(
        [("Content-Type", content_type), ("Content-Length", str(len(body))), ("Cache-Control", "no-store"),
         ("Connection", "close")]
    )
    return Response(status.value, status.phrase, headers, body)
