"""A latent step decides speech acts for at most WORDS_PER_LATENT words; the rest wait, in order, for the next steps
(one client's words cannot stall the stream's thread for a long step)."""

from types import SimpleNamespace

from gesturecast.controls import Gesture, Word, Words
from gesturecast.models.motion.root_anchor import RootAnchor, RootMode
from gesturecast.realtime.generation.generator import GeneratorSettings
from gesturecast.realtime.pose.session_controls import WORDS_PER_LATENT, SessionControls


class WordDoor:
    """A stream's gestures that record what reaches the cue plan, per latent step."""

    names = ("wave",)

    def __init__(self) -> None:
        self.steps: list[list] = [[]]

    def check_gesture(self, name: str) -> None:
        pass

    def check_lexicon(self) -> None:
        pass

    def check_live_words(self, words: tuple[Word, ...]) -> None:
        pass

    def stroke_lead_s(self) -> float:
        return 0.0

    def cue_gesture(self, name: str, t: float) -> None:
        self.steps[-1].append(name)

    def hear_words(self, words: tuple[Word, ...], wait: bool = True) -> None:
        self.steps[-1].extend(word.text for word in words)


def words(first: int, count: int) -> Words:
    return Words(tuple(Word(f"w{i}", 0.1 * i, 0.1 * i) for i in range(first, first + count)))


def controls_with(door: WordDoor) -> SessionControls:
    generator = SimpleNamespace(base_guidance=1.0, settings=GeneratorSettings())
    return SessionControls(generator, RootAnchor(RootMode.BOUNDED, fps=30.0), door)


def test_a_flood_of_words_is_spread_over_the_steps_in_order():
    door = WordDoor()
    controls = controls_with(door)
    controls.submit((words(0, 2 * WORDS_PER_LATENT + 10),))
    controls.submit((Gesture("wave"), words(100, 5)))
    for step in range(4):
        controls.advance(step * 0.133)
        door.steps.append([])
    applied = [len(step) for step in door.steps[:4]]
    assert applied == [WORDS_PER_LATENT, WORDS_PER_LATENT, 10 + 1 + 5, 0]
    flat = [name for step in door.steps for name in step]
    assert flat == [f"w{i}" for i in range(2 * WORDS_PER_LATENT + 10)] + ["wave"] + [f"w{i}" for i in range(100, 105)]
    assert controls.deferred_word_steps == (WORDS_PER_LATENT + 10 + 5) + (10 + 5)


def test_words_within_the_budget_all_apply_in_the_next_step():
    door = WordDoor()
    controls = controls_with(door)
    for first in range(0, WORDS_PER_LATENT, 10):
        controls.submit((words(first, 10),))
    controls.advance(0.0)
    assert len(door.steps[0]) == WORDS_PER_LATENT and controls.deferred_word_steps == 0
