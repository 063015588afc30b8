"""Thin transports shared by the UDP bridges: a connected UDP socket, a send-rate limiter, and
an error throttle so a failing send produces one log line per burst, never a crash. A missing receiver
(nothing listening on the port) is said once per sender, with a hint, and only counted after that."""

from __future__ import annotations

import logging
import socket
from collections.abc import Sequence
from dataclasses import dataclass

from gesturecast.bridges.osc_wire import IPV4_MAX_DATAGRAM_SIZE, IPV6_MAX_DATAGRAM_SIZE
from gesturecast.errors import UserError

logger = logging.getLogger(__name__)

LOG_EVERY_N_ERRORS = 300  # about 10 s of failed frames at 30 fps
SUPPORTED_SEND_RATES = (30.0, 60.0)
RATE_TOLERANCE = 0.25  # a frame may arrive up to this fraction of a period early and still be sent
# what a send raises once the receiver's host answered "port unreachable" (ICMP): nobody is listening there
# (Linux and macOS raise ConnectionRefusedError; Windows reports it as a reset connection)
NOBODY_LISTENING = (ConnectionRefusedError, ConnectionResetError)


class ErrorThrottle:
    """Logs the first error of a kind, then one summary line every ``every`` errors."""

    def __init__(self, what: str, every: int = LOG_EVERY_N_ERRORS) -> None:
        self.what = what
        self.every = every
        self.count = 0

    def report(self, error: BaseException) -> None:
        self.count += 1
        if self.count == 1 or self.count % self.every == 0:
            logger.warning("%s: %s (%d failures so far; the stream keeps going)", self.what, error, self.count)


class RateLimiter:
    """Passes frames at no more than ``rate`` per second, by their presentation time."""

    def __init__(self, rate: float) -> None:
        if rate not in SUPPORTED_SEND_RATES:
            raise UserError(f"send rate {rate:g} is not supported; use one of {SUPPORTED_SEND_RATES}")
        self.period = 1.0 / rate
        self._next_time: float | None = None

    def admit(self, presentation_time: float) -> bool:
        if self._next_time is not None and presentation_time < self._next_time - RATE_TOLERANCE * self.period:
            return False
        base = presentation_time if self._next_time is None else max(self._next_time, presentation_time)
        self._next_time = base + self.period
        return True


@dataclass(frozen=True)
class UdpTarget:
    host: str = "127.0.0.1"
    port: int = 39539


def max_datagram_size(family: int) -> int:
    """The largest UDP payload that crosses a 1500-byte Ethernet MTU unfragmented to an address of ``family``:
    1472 bytes over IPv4, 1452 over IPv6 (its header is 20 bytes longer)."""
    return IPV6_MAX_DATAGRAM_SIZE if family == socket.AF_INET6 else IPV4_MAX_DATAGRAM_SIZE


class UdpSender:
    """A UDP socket connected to one target. Connected, so ICMP "port unreachable" surfaces as
    ConnectionRefusedError on a later send: that is logged once ("nobody is listening", with ``hint``) and
    counted in :attr:`refused`; any other send error is throttled-logged and counted. Nothing is raised.
    :attr:`max_datagram_size` is the unfragmented payload limit for the resolved target's address family."""

    def __init__(self, target: UdpTarget, label: str, hint: str = "") -> None:
        try:
            family, kind, proto, _, address = socket.getaddrinfo(target.host, target.port, type=socket.SOCK_DGRAM)[0]
        except (socket.gaierror, OverflowError) as error:
            where = f"{target.host}:{target.port}"
            raise UserError(f"{label}: cannot resolve {where} ({error}); check the host name given to "
                            f"--{label.lower()}") from None
        self._socket = socket.socket(family, kind, proto)
        self.max_datagram_size = max_datagram_size(family)
        self._socket.setblocking(False)
        self._socket.connect(address)
        self.errors = ErrorThrottle(f"{label} send to {target.host}:{target.port} failed")
        self.sent_datagrams = 0
        self.refused = 0  # datagrams lost because nobody listened on the target port
        self._nobody_listening = f"nobody is listening on {target.host}:{target.port} ({label})" + (
            f"; {hint}" if hint else "")

    def send_all(self, datagrams: Sequence[bytes]) -> None:
        for datagram in datagrams:
            try:
                self._socket.send(datagram)
                self.sent_datagrams += 1
            except NOBODY_LISTENING:
                self.refused += 1
                if self.refused == 1:
                    logger.warning("%s (said once; the stream keeps going)", self._nobody_listening)
            except OSError as error:  # full buffer, network down
                self.errors.report(error)

    def counters(self) -> dict[str, int]:
        """Datagrams not delivered: refused (nobody listening) and failed otherwise."""
        return {"refused_datagrams": self.refused, "failed_datagrams": self.errors.count}

    def close(self) -> None:
        self._socket.close()
