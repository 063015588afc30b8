"""The stream's style and what the generator hears of it.

The session's controls own the style a stream is in (:class:`StyleState`): the stylizer and the face perform it.
The denoiser is told only what it conditions on, decided here by :meth:`StyleHearing.heard` (docs/architecture.md,
"The style's one way"): a label it learned with speech (a paired speech take's style: ``speech``, ``flirty`` …) it
hears itself, at the style strength k; every style the stylizer gives it hears as the generator style (``speech``,
``Settings.generator_style``), and the stylizer after it gives k, so the generator's guidance stays s. Every style the
generator is told passes through this one rule: the settings it is made with and each live change.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from gesturecast.models.generator.style_prompt import PartStyles, StylePrompt
from gesturecast.models.generator.styles import canonical_style
from gesturecast.settings import DEFAULT_STYLE_STRENGTH, SINGLE_STYLE

if TYPE_CHECKING:
    from gesturecast.realtime.generation.generator import GeneratorSettings

STYLIZER_STRENGTH = 1.0  # the generator's k when the stylizer gives the style: its guidance is s, the stylizer's k


@dataclass(frozen=True)
class StyleState:
    """The style a stream is in, owned by its controls: what the stylizer and the face perform (and, through
    :meth:`StyleHearing.heard`, what the generator hears)."""

    style: StylePrompt
    second_style: StylePrompt | None = None  # c2 of x̂0 = γ·D(style) + (1 − γ)·D(second_style), also while blending
    gamma: float = SINGLE_STYLE
    part_styles: PartStyles = ()
    strength: float = DEFAULT_STYLE_STRENGTH

    @staticmethod
    def of(settings: GeneratorSettings) -> StyleState:
        """The style the settings a generator was made with ask for (a generator alone hears every style as asked)."""
        return StyleState(settings.style, settings.second_style, settings.gamma, tuple(settings.part_styles),
                          settings.style_strength)

    def prompts(self) -> list[StylePrompt]:
        """Every prompt of the state: the style, the second style, the part styles."""
        second = [] if self.second_style is None else [self.second_style]
        return [self.style, *second, *(prompt for _, prompt in self.part_styles)]


@dataclass(frozen=True)
class StyleHearing:
    """The rule from a style asked to the style the denoiser hears. ``generator_style``: the label heard for every
    style the stylizer gives (None: every style is heard as asked, the generator alone with no stylizer after it);
    ``own_labels``: the labels heard as asked even so, the paired speech takes' styles, which the stylizer does not
    give."""

    generator_style: StylePrompt | None = None
    own_labels: frozenset[str] = frozenset()

    def hears_as_asked(self, prompt: StylePrompt) -> bool:
        """Whether the denoiser hears this style itself (else the generator style, the stylizer giving it)."""
        if self.generator_style is None:
            return True
        return prompt.kind == "label" and canonical_style(prompt.value) in self.own_labels

    def prompt(self, prompt: StylePrompt) -> StylePrompt:
        """The prompt the denoiser hears for a style asked."""
        return prompt if self.hears_as_asked(prompt) else self.generator_style

    def heard(self, state: StyleState) -> StyleState:
        """What the generator is told of ``state``: each prompt as heard, γ as asked, and the strength k when it
        hears the main style itself (1: the stylizer gives k)."""
        second = None if state.second_style is None else self.prompt(state.second_style)
        parts = tuple((part, self.prompt(prompt)) for part, prompt in state.part_styles)
        strength = state.strength if self.hears_as_asked(state.style) else STYLIZER_STRENGTH
        return StyleState(self.prompt(state.style), second, state.gamma, parts, strength)
