"""OSC input: gestures, gesture size and pause from a Stream Deck, TouchOSC, VNyan or a game engine
(``live --osc-in [HOST:]PORT``).

Three addresses are understood, each with one value, plus the shared token as a second string when the port listens
beyond loopback (the same rule as the WebSocket controls: :func:`gesturecast.bridges.ws_access.check_exposure`):

- ``/gesturecast/gesture`` with the gesture's name as a string (``,s "wave"``);
- ``/gesturecast/intensity`` with the gesture size as a number (``,f 0.5``: 0 stands and breathes, 1 as generated, 2);
- ``/gesturecast/pause`` with 1 (or 1.0, a toggle's "on") to send the body to the idle pose, 0 to resume.

Bundles are unpacked. Anything else (another address, other arguments, a malformed datagram, a wrong token) is
dropped and counted; the first of each kind is logged once. A message becomes the typed control of its field
(checked by :func:`gesturecast.controls.parse_controls`, as every door's controls are) handed to ``on_control`` (the
session's controls: a gesture's name checked against the lexicon there, carried out at the next latent), so an
unknown name or a size out of range is logged and the stream goes on.

The decoder is the project's own: OSC 1.0 strings (NUL-terminated, padded to 4 bytes), ``i`` / ``f`` / ``s``
arguments, ``#bundle`` elements, nothing else.
"""

from __future__ import annotations

import logging
import socket
import struct
import threading
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass

from gesturecast.bridges.osc_wire import BUNDLE_HEADER_SIZE, BUNDLE_TAG, ELEMENT_SIZE_PREFIX, OSC_ALIGNMENT
from gesturecast.bridges.ws_access import check_exposure, tokens_match
from gesturecast.controls import Control, parse_controls
from gesturecast.errors import UserError

logger = logging.getLogger(__name__)

GESTURE_ADDRESS = "/gesturecast/gesture"
INTENSITY_ADDRESS = "/gesturecast/intensity"
PAUSE_ADDRESS = "/gesturecast/pause"
CONTROL_ADDRESSES = {GESTURE_ADDRESS: "gesture", INTENSITY_ADDRESS: "intensity", PAUSE_ADDRESS: "pause"}  # -> field
MAX_DATAGRAM = 65507  # the largest UDP payload
MAX_BUNDLE_DEPTH = 4
RECEIVE_TIMEOUT_S = 0.2  # how often the listener looks for close()
OscArgument = str | int | float


class OscFormatError(ValueError):
    """A datagram that is not OSC 1.0 as this decoder reads it."""


def _string(data: bytes, start: int) -> tuple[str, int]:
    """The padded OSC string at ``start`` and the offset after its padding."""
    end = data.find(b"\x00", start)
    if end < 0:
        raise OscFormatError("unterminated string")
    try:
        text = data[start:end].decode("utf-8")
    except UnicodeDecodeError:
        raise OscFormatError("a string is not UTF-8") from None
    return text, (end // OSC_ALIGNMENT + 1) * OSC_ALIGNMENT


def parse_message(data: bytes) -> tuple[str, list[OscArgument]]:
    """One OSC message → (address, arguments)."""
    address, offset = _string(data, 0)
    if not address.startswith("/"):
        raise OscFormatError("the address does not start with '/'")
    tags, offset = _string(data, offset) if offset < len(data) else (",", offset)
    if not tags.startswith(","):
        raise OscFormatError("no type tag string")
    arguments: list[OscArgument] = []
    for tag in tags[1:]:
        if tag == "s":
            text, offset = _string(data, offset)
            arguments.append(text)
        elif tag in "if" and offset + 4 <= len(data):
            arguments.append(struct.unpack_from(">i" if tag == "i" else ">f", data, offset)[0])
            offset += 4
        else:
            raise OscFormatError(f"argument type {tag!r} is not read here (or the datagram is short)")
    return address, arguments


def parse_datagram(data: bytes, depth: int = 0) -> list[tuple[str, list[OscArgument]]]:
    """A datagram's messages: one message, or every element of a bundle (nested up to MAX_BUNDLE_DEPTH)."""
    if not data.startswith(BUNDLE_TAG):
        return [parse_message(data)]
    if depth >= MAX_BUNDLE_DEPTH:
        raise OscFormatError("bundles nested too deeply")
    messages, offset = [], BUNDLE_HEADER_SIZE
    while offset < len(data):
        if offset + ELEMENT_SIZE_PREFIX > len(data):
            raise OscFormatError("truncated bundle element")
        (size,) = struct.unpack_from(">i", data, offset)
        offset += ELEMENT_SIZE_PREFIX
        if size <= 0 or offset + size > len(data):
            raise OscFormatError("bundle element size out of range")
        messages += parse_datagram(data[offset : offset + size], depth + 1)
        offset += size
    return messages


@dataclass(frozen=True)
class OscInConfig:
    host: str = "127.0.0.1"
    port: int = 9001
    token: str | None = None  # needed beyond loopback, sent as the message's second string


def control_value(field: str, argument: OscArgument) -> OscArgument | bool:
    """The control value of a message's argument: a pause's number (0 / 1, a toggle's 0.0 / 1.0) as false / true."""
    if field == "pause" and isinstance(argument, (int, float)):
        return bool(argument)
    return argument


class OscControlListener:
    """A UDP port whose control messages become controls (see the module docstring)."""

    def __init__(self, config: OscInConfig, on_control: Callable[[tuple[Control, ...]], None]) -> None:
        check_exposure(config.host, config.token)
        self.config = config
        self.on_control = on_control
        self.counts: Counter[str] = Counter()  # received, controls, dropped kinds
        self._socket = socket.socket(socket.AF_INET6 if ":" in config.host else socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self._socket.bind((config.host, config.port))
        except OSError as error:
            self._socket.close()
            raise UserError(f"--osc-in {config.host}:{config.port}: cannot listen there ({error.strerror}); "
                            "pick another port") from None
        self._socket.settimeout(RECEIVE_TIMEOUT_S)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._receive, name="osc-in", daemon=True)

    @property
    def port(self) -> int:
        return self._socket.getsockname()[1]

    def start(self) -> OscControlListener:
        self._thread.start()
        logger.info("controls by OSC on %s:%d (%s NAME, %s SIZE, %s 0|1)", self.config.host, self.port,
                    GESTURE_ADDRESS, INTENSITY_ADDRESS, PAUSE_ADDRESS)
        return self

    def close(self) -> None:
        """Stop listening (also when never started)."""
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()
        self._socket.close()

    def _receive(self) -> None:
        while not self._stop.is_set():
            try:
                data = self._socket.recv(MAX_DATAGRAM)
            except TimeoutError:
                continue
            except OSError:
                return
            self.handle(data)

    def handle(self, data: bytes) -> None:
        """One datagram: its gesture messages become controls; the rest is dropped and counted."""
        self.counts["received"] += 1
        try:
            messages = parse_datagram(data)
        except OscFormatError as error:
            return self._drop("malformed", f"a malformed OSC datagram ({error})")
        for address, arguments in messages:
            self._message(address, arguments)

    def _message(self, address: str, arguments: list[OscArgument]) -> None:
        field = CONTROL_ADDRESSES.get(address)
        if field is None:
            return self._drop("other_address", f"OSC address {address!r:.60} (only {', '.join(CONTROL_ADDRESSES)} "
                              "are read)")
        wanted = 1 if self.config.token is None else 2
        if len(arguments) != wanted or not all(isinstance(a, str) for a in arguments[1:]):
            return self._drop("bad_arguments", f"{address} wants one value"
                              + (" and the token as a string" if self.config.token else ""))
        if self.config.token is not None and not tokens_match(arguments[1], self.config.token):
            return self._drop("wrong_token", f"{address} with a wrong token")
        try:
            self.on_control(parse_controls({field: control_value(field, arguments[0])}))
        except (UserError, ValueError) as error:
            return self._drop("refused", f"{field} {arguments[0]!r:.40} refused: {error}")
        self.counts["controls"] += 1

    def dropped(self) -> dict[str, int]:
        """The messages dropped so far by kind, named for the run's summary and report (``osc_in_wrong_token``)."""
        return {f"osc_in_{kind}": count for kind, count in self.counts.items() if kind not in ("received", "controls")}

    def _drop(self, kind: str, description: str) -> None:
        self.counts[kind] += 1
        if self.counts[kind] == 1:
            logger.warning("ignored %s (said once; later ones are counted)", description)
