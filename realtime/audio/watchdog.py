"""Stalled-microphone watchdog: a device that delivers no samples is reported, then waited for, then given up.

A USB or Bluetooth microphone that stalls, a suspended PulseAudio source or a muted virtual device
opens fine and then delivers nothing. Without a watchdog the live engine would produce nothing and
say nothing. :class:`StallWatchdog` is pure logic on the caller's times (no clock, no thread):

- no audio for ``warn_s`` seconds → one warning line naming the device;
- audio again → one line saying it is back (the stream goes on);
- no audio for ``timeout_s`` seconds → :class:`UserError` (the run ends with one error line).
"""

from __future__ import annotations

import logging

from gesturecast.errors import UserError

logger = logging.getLogger(__name__)

STALL_WARN_S = 2.0  # silence from the device (no samples at all, not quiet samples) before the warning
DEFAULT_STALL_TIMEOUT_S = 10.0  # silence from the device before the run ends with an error


class StallWatchdog:
    """Tracks the time of the newest samples from one device; see the module docstring for the rule."""

    def __init__(self, device_label: str, now: float, timeout_s: float = DEFAULT_STALL_TIMEOUT_S,
                 warn_s: float = STALL_WARN_S) -> None:
        self.device_label = device_label
        self.timeout_s = timeout_s
        self.warn_s = min(warn_s, timeout_s)
        self._last_audio = now
        self._warned = False

    @property
    def stalled(self) -> bool:
        """Whether the warning has been given and no audio has come since."""
        return self._warned

    def audio(self, now: float) -> None:
        """Samples arrived at ``now``."""
        if self._warned:
            logger.warning("audio from %s is back after %.1f s without samples", self.device_label,
                           now - self._last_audio)
            self._warned = False
        self._last_audio = now

    def silence(self, now: float) -> None:
        """A read at ``now`` found no samples: warn once, or raise once the timeout has passed."""
        quiet_s = now - self._last_audio
        if quiet_s >= self.timeout_s:
            raise UserError(
                f"{self.device_label} delivered no audio for {quiet_s:.1f} s (stalled, unplugged or suspended?); "
                "check the microphone, pick another with --device, or wait longer with --stall-timeout SECONDS"
            )
        if quiet_s >= self.warn_s and not self._warned:
            logger.warning("no audio from %s for %.1f s (stalled or suspended microphone?); waiting up to %.0f s "
                           "for it", self.device_label, quiet_s, self.timeout_s)
            self._warned = True
