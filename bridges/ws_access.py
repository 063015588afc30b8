"""Who may use a WebSocket port: browser origins, the token, and a per-address limit on wrong tokens.

Shared by the viewer bridge (``live --ws``) and ``gesturecast serve``:

- **Origin.** A browser always sends ``Origin`` with a WebSocket upgrade; other clients usually do not.
  An upgrade with no ``Origin`` is accepted (as before). One with an ``Origin`` is accepted only from the
  port's own origin (``http://HOST:PORT``; on loopback also its ``127.0.0.1`` / ``localhost`` / ``[::1]``
  spellings) or from an ``--allow-origin`` entry; any other page gets HTTP 403. This stops a page on
  another site, open in the user's browser, from steering the loopback server (cross-site WebSocket
  hijacking). Host names are compared exactly, so a DNS-rebound name is not the server's origin.
- **Token.** At least :data:`MIN_TOKEN_CHARS` characters with :data:`MIN_DISTINCT_TOKEN_CHARS`
  different ones; compared as UTF-8 bytes in constant time (any Unicode token works).
- **Wrong tokens.** The connection that sent one is closed; a client that sent
  :data:`MAX_TOKEN_FAILURES` wrong tokens within :data:`TOKEN_FAILURE_WINDOW_S` gets HTTP 429 on its
  next connections until the window has passed. Clients are told apart by :func:`client_key`: a remote
  peer by its address; a peer on this machine (loopback or a Unix socket: a reverse proxy, or a local app) by the
  address its proxy appended last to ``X-Forwarded-For`` (the client's own, which the client cannot forge: the
  entries before it it can), or, without that header, by its ``User-Agent``, so one bad client behind a proxy,
  or one bad local app, does not lock out the others. ``serve --workers`` counts across its workers
  (:class:`gesturecast.realtime.serve.shared_failures.SharedFailedTokens`).
"""

from __future__ import annotations

import hmac
import ipaddress
import os
from collections import OrderedDict, deque
from collections.abc import Callable, Iterable, Mapping
from http import HTTPStatus
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import urlsplit

from websockets.datastructures import Headers
from websockets.frames import CloseCode
from websockets.http11 import Request, Response

from gesturecast.bridges.ws_protocol import error_message
from gesturecast.controls import ControlError
from gesturecast.errors import UserError
from gesturecast.input_files import read_bounded

if TYPE_CHECKING:  # asyncio and the server load only where a server runs (`generate` never needs them)
    from websockets.asyncio.server import ServerConnection

LOOPBACK_NAMES = frozenset({"localhost"})
MIN_TOKEN_CHARS = 16
MIN_DISTINCT_TOKEN_CHARS = 8
TOKEN_ENV_VAR = "GESTURECAST_TOKEN"
MAX_TOKEN_FILE_BYTES = 4096  # a token is one short line; more is not a token file (``/dev/zero`` read 4.4 GB)
MAX_TOKEN_FAILURES = 5
TOKEN_FAILURE_WINDOW_S = 60.0
MAX_TRACKED_ADDRESSES = 1024  # the failure table is bounded: the longest-quiet client is forgotten first
MAX_CLIENT_KEY_CHARS = 200  # a User-Agent is the key of a local app: its first characters are enough
FORWARDED_FOR = "X-Forwarded-For"
LOOPBACK_ORIGIN_HOSTS = ("127.0.0.1", "localhost", "[::1]")
ORIGIN_SCHEMES = ("http", "https")
TOKEN_HINT = "e.g. python3 -c 'import secrets; print(secrets.token_urlsafe(24))'"


class WrongToken(ControlError):
    """A wrong token: answered with an ``error``, then the connection is closed (and counted)."""


def is_loopback(host: str) -> bool:
    if host in LOOPBACK_NAMES:
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def check_exposure(host: str, token: str | None) -> None:
    """UserError when a server would listen beyond loopback without a token, or with a weak one."""
    if not is_loopback(host) and not token:
        raise UserError(f"listening on {host} exposes the server beyond this machine; give a token too "
                        f"(--token-file FILE or the {TOKEN_ENV_VAR} variable)")
    if token is not None:
        check_token_strength(token)


def check_token_strength(token: str) -> None:
    """UserError unless ``token`` is long and varied enough to resist guessing."""
    if len(token) < MIN_TOKEN_CHARS or len(set(token)) < MIN_DISTINCT_TOKEN_CHARS:
        raise UserError(f"the token is too weak: use at least {MIN_TOKEN_CHARS} characters with at least "
                        f"{MIN_DISTINCT_TOKEN_CHARS} different ones ({TOKEN_HINT})")


def tokens_match(given: object, expected: str) -> bool:
    """Constant-time comparison of a client's token with the server's (any Unicode, as UTF-8 bytes)."""
    return isinstance(given, str) and hmac.compare_digest(given.encode("utf-8", "surrogatepass"),
                                                          expected.encode("utf-8", "surrogatepass"))


def token_from_sources(flag: str | None, file: Path | None, environ: Mapping[str, str] = os.environ) -> str | None:
    """The token from ``--token``, ``--token-file`` or the ``GESTURECAST_TOKEN`` variable (at most one of
    the flags; a flag wins over the variable). A file's surrounding whitespace (its newline) is dropped."""
    if flag is not None and file is not None:
        raise UserError("give the token once: --token or --token-file, not both")
    if file is not None:
        return _read_token_file(file)
    if flag is not None:
        return flag
    return environ.get(TOKEN_ENV_VAR) or None


def _read_token_file(path: Path) -> str:
    """The token in ``path`` (at most :data:`MAX_TOKEN_FILE_BYTES` read), surrounding whitespace dropped."""
    data = read_bounded(path, MAX_TOKEN_FILE_BYTES, "the token file")
    try:
        token = data.decode("utf-8").strip()
    except UnicodeDecodeError as error:
        raise UserError(f"cannot read the token file {path}: {error}") from None
    if not token:
        raise UserError(f"the token file {path} is empty")
    return token


def normalize_origin(origin: str) -> str:
    """``HTTP://LocalHost:8765/`` → ``http://localhost:8765`` (scheme and host are case-insensitive)."""
    return origin.strip().rstrip("/").lower()


def check_origins(origins: Iterable[str]) -> tuple[str, ...]:
    """``--allow-origin`` values, normalised; UserError for anything that is not ``scheme://host[:port]``."""
    checked = []
    for origin in origins:
        parts = urlsplit(normalize_origin(origin))
        if parts.scheme not in ORIGIN_SCHEMES or not parts.netloc or parts.path or parts.query:
            raise UserError(f"--allow-origin wants scheme://host[:port] (e.g. http://localhost:3000), got {origin!r}")
        checked.append(normalize_origin(origin))
    return tuple(checked)


def own_origins(host: str, port: int, loopback: bool) -> frozenset[str]:
    """The origins of pages served by this port itself (all loopback spellings when on loopback)."""
    hosts = LOOPBACK_ORIGIN_HOSTS if loopback else (f"[{host}]" if ":" in host else host,)
    return frozenset(normalize_origin(f"http://{name}:{port}") for name in hosts)


def refusal(status: HTTPStatus, reason: str) -> Response:
    """A plain-text HTTP refusal of a handshake."""
    body = f"{reason}\n".encode()
    headers = Headers([("Content-Type", "text/plain; charset=utf-8"), ("Content-Length", str(len(body))),
                       ("Connection", "close")])
    return Response(status.value, status.phrase, headers, body)


class FailedTokens:
    """Wrong tokens per client (:func:`client_key`) within a sliding window (bounded table, injected clock)."""

    def __init__(self, clock: Callable[[], float], limit: int = MAX_TOKEN_FAILURES,
                 window_s: float = TOKEN_FAILURE_WINDOW_S) -> None:
        self.clock = clock
        self.limit = limit
        self.window_s = window_s
        self._failures: OrderedDict[str, deque[float]] = OrderedDict()

    def record(self, address: str) -> None:
        times = self._failures.pop(address, None) or deque(maxlen=self.limit)
        times.append(self.clock())
        self._failures[address] = times  # most recent last
        while len(self._failures) > MAX_TRACKED_ADDRESSES:
            self._failures.popitem(last=False)

    def blocked(self, address: str) -> bool:
        """True while ``address`` has ``limit`` failures younger than the window."""
        times = self._failures.get(address)
        if times is None:
            return False
        expired = self.clock() - self.window_s
        while times and times[0] <= expired:
            times.popleft()
        return len(times) >= self.limit


class AccessPolicy:
    """Origin check, token and wrong-token limit for one listening port. :meth:`process_request` is the
    websockets handshake hook (a refusal, or None to go on); :meth:`verify_token` checks a message's token."""

    def __init__(self, host: str, token: str | None, allow_origins: Iterable[str], clock: Callable[[], float],
                 failures: FailedTokens | None = None) -> None:
        check_exposure(host, token)
        self.host = host
        self.token = token
        self.loopback = is_loopback(host)
        self.allow_origins = frozenset(check_origins(allow_origins))
        self.failures = failures or FailedTokens(clock)  # serve --workers: a table every worker shares

    @property
    def token_required(self) -> bool:
        """A token, once given, is always checked; beyond loopback one must be given (check_exposure)."""
        return self.token is not None or not self.loopback

    def origin_allowed(self, origin: str | None, port: int) -> bool:
        if origin is None:
            return True  # not a browser: the token (when set) is the guard
        normalized = normalize_origin(origin)
        return normalized in self.allow_origins or normalized in own_origins(self.host, port, self.loopback)

    def process_request(self, connection: ServerConnection, request: Request) -> Response | None:
        origin = request.headers.get("Origin")
        if not self.origin_allowed(origin, local_port(connection)):
            return refusal(HTTPStatus.FORBIDDEN, f"origin {origin} is not allowed; start the server with "
                                                  f"--allow-origin {origin} to let its pages connect")
        if self.failures.blocked(client_key(connection, request.headers)):
            return refusal(HTTPStatus.TOO_MANY_REQUESTS,
                           f"too many wrong tokens from this client; wait {TOKEN_FAILURE_WINDOW_S:g} s")
        return None

    def verify_token(self, connection: ServerConnection, message: dict) -> None:
        """ControlError when ``message`` lacks the token; WrongToken (counted) when it carries another."""
        if not self.token_required:
            return
        given = message.get("token")
        if given is None:
            raise ControlError('this server needs a token: add "token" to the message')
        if not tokens_match(given, self.token or ""):
            self.failures.record(client_key(connection, connection.request.headers))
            raise WrongToken("wrong token; closing the connection")


async def send_refusal(connection: ServerConnection, error: ControlError) -> None:
    """Answer a refused message with one ``error`` line; a wrong token also closes the connection (1008)."""
    await connection.send(error_message(str(error)))
    if isinstance(error, WrongToken):
        await connection.close(CloseCode.POLICY_VIOLATION, str(error))


def local_port(connection: ServerConnection) -> int:
    """The port the peer connected to; 0 for a connection without one (a Unix socket)."""
    address = connection.local_address
    return int(address[1]) if isinstance(address, tuple) and len(address) > 1 else 0


def client_address(connection: ServerConnection) -> str:
    """The peer's IP address (its port changes with every connection, so it is not part of the key); ``local`` for
    a peer without one (a Unix socket)."""
    address = connection.remote_address
    return str(address[0]) if isinstance(address, tuple) and address else "local"


def client_key(connection: ServerConnection, headers: Headers) -> str:
    """Whose wrong tokens a connection counts toward (module docstring): a remote peer's address; for a peer on this
    machine the last address of ``X-Forwarded-For`` (what its proxy appended), else ``local|loopback UA``."""
    address = client_address(connection)
    if address != "local" and not is_loopback(address):
        return address
    forwarded = [part.strip() for line in headers.get_all(FORWARDED_FOR) for part in line.split(",") if part.strip()]
    if forwarded:
        return forwarded[-1][:MAX_CLIENT_KEY_CHARS]
    return f"{address} {headers.get('User-Agent', '')}"[:MAX_CLIENT_KEY_CHARS]
