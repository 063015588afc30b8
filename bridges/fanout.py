"""Send every PoseFrame to all configured bridges; one failing bridge never stops the others."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from gesturecast.bridges.transport import ErrorThrottle
from gesturecast.frames import PoseFrame


class Bridge(Protocol):
    name: str

    def send(self, frame: PoseFrame) -> None: ...

    def close(self) -> None: ...


class BridgeFanout:
    """Calls ``send`` on each bridge in turn. An exception from one bridge is logged (first one,
    then every N-th, per bridge) and counted; the frame still reaches every other bridge."""

    def __init__(self, bridges: Sequence[Bridge]) -> None:
        self.bridges = tuple(bridges)
        self._errors = {id(bridge): ErrorThrottle(f"bridge {bridge.name!r} failed") for bridge in self.bridges}
        self.close_errors: list[str] = []  # what closing the bridges raised (e.g. a recording not saved)

    def send(self, frame: PoseFrame) -> None:
        for bridge in self.bridges:
            try:
                bridge.send(frame)
            except Exception as error:  # isolation boundary: any bridge failure stays inside that bridge
                self._errors[id(bridge)].report(error)

    def counters(self) -> dict[str, dict[str, int]]:
        """Per bridge that keeps delivery counters (``counters()``, e.g. WebSocket drops and skips): those counters."""
        return {bridge.name: bridge.counters() for bridge in self.bridges if hasattr(bridge, "counters")}

    def failures(self) -> dict[str, int]:
        return {bridge.name: self._errors[id(bridge)].count for bridge in self.bridges}

    def close(self) -> None:
        """Close every bridge; what a bridge raises is kept in :attr:`close_errors` for the final summary."""
        for bridge in self.bridges:
            try:
                bridge.close()
            except Exception as error:  # a broken bridge must not keep the others open
                self._errors[id(bridge)].report(error)
                self.close_errors.append(str(error))
