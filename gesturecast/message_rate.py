"""Per-connection rate limits on control and ``words`` messages: one client cannot flood a stream with work.

Two token buckets per connection (Turner 1986): one for messages (control and words alike), one for the words
they carry (deciding speech acts costs about a millisecond a word, on the stream's thread). A message over either
limit is refused whole with an ``error`` that says so and when to try again; the connection and every stream go on,
and the buckets refill at their rate. Time comes from the injected clock.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from gesturecast.controls import Control, ControlError, Words

MESSAGES_PER_S = 20.0  # control and words messages a connection may send per second, on average
MESSAGE_BURST = 40  # and at once after a pause
WORDS_PER_S = 100.0  # words per second on average: about 30 times a fast speaker
WORD_BURST = 600  # and at once: a long reply's transcript in one message


@dataclass(frozen=True)
class RateLimits:
    messages_per_s: float = MESSAGES_PER_S
    message_burst: int = MESSAGE_BURST
    words_per_s: float = WORDS_PER_S
    word_burst: int = WORD_BURST


class TokenBucket:
    """``burst`` tokens at most, refilled at ``rate`` per second of the clock."""

    def __init__(self, rate: float, burst: int, now: float) -> None:
        self.rate = rate
        self.burst = burst
        self._tokens = float(burst)
        self._time = now

    def level(self, now: float) -> float:
        self._tokens = min(float(self.burst), self._tokens + (now - self._time) * self.rate)
        self._time = now
        return self._tokens

    def wait_s(self, cost: float, now: float) -> float:
        """Seconds until ``cost`` tokens are there (0: now)."""
        return max(0.0, (cost - self.level(now)) / self.rate)

    def take(self, cost: float) -> None:
        self._tokens -= cost


class MessageRate:
    """One connection's buckets: :meth:`admit` takes a message's cost or refuses it with a ControlError."""

    def __init__(self, clock: Callable[[], float], limits: RateLimits | None = None) -> None:
        self.clock = clock
        self.limits = limits or RateLimits()
        now = clock()
        self.messages = TokenBucket(self.limits.messages_per_s, self.limits.message_burst, now)
        self.words = TokenBucket(self.limits.words_per_s, self.limits.word_burst, now)
        self.refused = 0

    def admit(self, controls: tuple[Control, ...]) -> None:
        """Charge one message carrying ``controls``; ControlError (nothing charged) when over a limit."""
        words = sum(len(control.words) for control in controls if isinstance(control, Words))
        if words > self.limits.word_burst:
            self._refuse(f"{words} words in one message; send at most {self.limits.word_burst} at a time")
        now = self.clock()
        wait_s = max(self.messages.wait_s(1, now), self.words.wait_s(words, now))
        if wait_s > 0.0:
            self._refuse(f"rate limit: at most {self.limits.messages_per_s:g} messages and "
                         f"{self.limits.words_per_s:g} words a second; try again in {wait_s:.2f} s")
        self.messages.take(1)
        self.words.take(words)

    def _refuse(self, reason: str) -> None:
        self.refused += 1
        raise ControlError(f"{reason} (this message was not applied; the stream goes on)")
