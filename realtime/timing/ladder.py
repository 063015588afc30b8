"""The degradation ladder: how much cheaper the next latent is made when the last ones used most of their margin.

Each paced burst reports the share of its compute margin it used (:data:`~gesturecast.realtime.run.engine.
STAGE_MARGIN_USED` over the margin: 1 means its first frame was ready exactly at its presentation time, more
means it was late). The ladder keeps a moving estimate of that share and steps one rung down (cheaper work)
when the estimate, or one burst alone, would miss; it climbs one rung back only after
:attr:`LadderConfig.climb_after` bursts in a row with slack, so it does not flap. Rung 0 is the full work; what
each further rung drops is :data:`gesturecast.realtime.generation.degradation.RUNGS` (docs/latency.md
"Degradation ladder"). A run that is never late stays on rung 0 and never touches the generator.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class LadderConfig:
    step_down_at: float = 0.9  # moving share of the margin used above this: one rung down
    late_at: float = 1.0  # one burst alone above this (it missed): one rung down at once
    climb_below: float = 0.5  # bursts under this share count toward climbing back
    climb_after: int = 16  # this many in a row (about 4 s of latents at 4 per second): one rung up
    smoothing: float = 0.25  # weight of the newest burst in the moving estimate


class DegradationLadder:
    """The rung the next latent is generated at, from the margin the bursts used; counts bursts per rung."""

    def __init__(self, rungs: int, config: LadderConfig | None = None) -> None:
        self.top = rungs - 1  # the cheapest rung
        self.config = config or LadderConfig()
        self.rung = 0
        self.counts = [0] * rungs  # bursts generated at each rung
        self.changes = 0
        self._estimate = 0.0
        self._slack_run = 0

    def observe(self, margin_share: float) -> int:
        """Record the burst just generated (at the current rung) and the share of its margin it used; returns the
        rung for the next one."""
        self.counts[self.rung] += 1
        config = self.config
        self._estimate += config.smoothing * (margin_share - self._estimate)
        self._slack_run = self._slack_run + 1 if margin_share < config.climb_below else 0
        if (margin_share > config.late_at or self._estimate > config.step_down_at) and self.rung < self.top:
            self._move(+1)
        elif self._slack_run >= config.climb_after and self.rung > 0:
            self._move(-1)
        return self.rung

    def _move(self, step: int) -> None:
        self.rung += step
        self.changes += 1
        self._slack_run = 0
        self._estimate = self.fresh_estimate  # the new rung is judged on its own bursts

    @property
    def fresh_estimate(self) -> float:
        """Where the moving estimate starts on a new rung: halfway between climbing and stepping down."""
        return (self.config.climb_below + self.config.step_down_at) / 2

    def to_dict(self) -> dict:
        return {"rung": self.rung, "bursts_per_rung": list(self.counts), "rung_changes": self.changes}
