"""The count of every sentence's alignment outcome, never silent: a throttled log line for each sentence that did not
align fully, and the counts for the run's summary and ``bench gestures``. A sentence whose words cue nothing is not
aligned at all (its words' times would change nothing): it is counted as ``uncued``."""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

from gesturecast.log_throttle import ThrottledLog
from gesturecast.realtime.words.aligner import FALLBACKS, METHODS, Alignment

logger = logging.getLogger(__name__)


@dataclass
class AlignmentCounts:
    """Sentences by outcome (:data:`~gesturecast.realtime.words.aligner.METHODS`, and ``uncued``) and their words."""

    sentences: dict[str, int] = field(default_factory=lambda: dict.fromkeys((*METHODS, "uncued"), 0))
    words: int = 0
    aligned_words: int = 0
    _log: ThrottledLog = field(default_factory=lambda: ThrottledLog(logger), repr=False, compare=False)

    def count(self, alignment: Alignment, text: str) -> None:
        """Count one sentence's alignment (of all its words, or of the first of them its cues need); one an alignment
        did not place fully is logged (at most a line per interval)."""
        self.sentences[alignment.method] += 1
        self.words += len(text.split())
        self.aligned_words += round(alignment.confidence * len(alignment.words))
        if alignment.method in FALLBACKS:
            self._log.log(logging.INFO, f"words placed by {alignment.method} ({alignment.confidence:.0%} aligned): "
                                        f"{text[:60]!r}")

    def count_uncued(self, words: int) -> None:
        """Count a sentence of ``words`` words that cues nothing, so it was not aligned."""
        self.sentences["uncued"] += 1
        self.words += words

    def to_dict(self) -> dict:
        """The counts as JSON-able data: ``{"aligned": n, "onset": n, "partly": n, "spread": n, "failed": n,
        "uncued": n, "words": n, "aligned_words": n}``."""
        return {**self.sentences, "words": self.words, "aligned_words": self.aligned_words}

    def describe(self) -> str:
        """One line: ``aligned 3, onset 2, partly 1, spread 0, failed 0, uncued 5 (41/98 words aligned)``."""
        outcomes = ", ".join(f"{method} {n}" for method, n in self.sentences.items())
        return f"{outcomes} ({self.aligned_words}/{self.words} words aligned)"

    def __bool__(self) -> bool:
        return self.words > 0
