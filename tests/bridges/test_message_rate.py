"""Per-connection rate limits on control and words messages, on a fake clock."""

import pytest

from gesturecast.controls import ControlError, StyleChange, Word, Words
from gesturecast.message_rate import MessageRate, RateLimits

LIMITS = RateLimits(messages_per_s=2.0, message_burst=4, words_per_s=10.0, word_burst=30)
CONTROL = (StyleChange(guidance=2.0),)


class Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def words(count: int) -> tuple[Words, ...]:
    return (Words(tuple(Word("hello", 0.1 * i, 0.1 * i) for i in range(count))),)


def admitted(rate: MessageRate, messages) -> list[bool]:
    results = []
    for message in messages:
        try:
            rate.admit(message)
            results.append(True)
        except ControlError:
            results.append(False)
    return results


def test_a_burst_passes_then_the_rest_are_refused_until_the_bucket_refills():
    clock = Clock()
    rate = MessageRate(clock, LIMITS)
    assert admitted(rate, [CONTROL] * 6) == [True] * 4 + [False] * 2
    clock.now = 0.5  # one message's worth at 2 a second
    assert admitted(rate, [CONTROL] * 2) == [True, False]
    assert rate.refused == 3


def test_words_are_limited_by_count_as_well_as_by_message():
    clock = Clock()
    rate = MessageRate(clock, LIMITS)
    assert admitted(rate, [words(20), words(20)]) == [True, False]  # 30 words at once, 10 a second after
    clock.now = 2.0
    assert admitted(rate, [words(20)]) == [True]


def test_the_refusal_says_what_the_limit_is_when_to_retry_and_that_the_stream_goes_on():
    clock = Clock()
    rate = MessageRate(clock, LIMITS)
    admitted(rate, [CONTROL] * 4)
    with pytest.raises(ControlError) as refused:
        rate.admit(CONTROL)
    message = str(refused.value)
    assert "at most 2 messages and 10 words a second" in message and "try again in 0.50 s" in message
    assert "the stream goes on" in message and "\n" not in message


def test_a_message_with_more_words_than_a_burst_is_refused_with_the_most_it_may_carry():
    rate = MessageRate(Clock(), LIMITS)
    with pytest.raises(ControlError, match="31 words in one message; send at most 30"):
        rate.admit(words(31))
    assert admitted(rate, [words(30)]) == [True]  # nothing was charged for the refused one
