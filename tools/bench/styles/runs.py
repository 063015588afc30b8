"""The generations a style study needs, each made once: one speech clip, many style requests.

A :class:`StyleRequest` is one way of asking for a style (a prompt, a guidance scale s, per-part prompts, a
seed); :class:`StudyRuns` generates it through the product's offline session
(:func:`gesturecast.tools.eval.generate.generate_offline`, DDIM K steps) and remembers the result,
so the single-style runs of the accuracy sweep are reused by the motion-prompt and per-part comparisons. These
sections study the generator's own style condition, so the runs hear the style asked and leave the stylizer out
(the ``stylizer`` section measures the product's path: :mod:`.stylizer_study`).
:meth:`StudyRuns.real_time_factor` generates afresh instead, for timing requests back to back.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.generator.style_prompt import PartStyles, StylePrompt
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.realtime.generation.generator import Generator, GeneratorSettings
from gesturecast.settings import DEFAULT_AUDIO_GUIDANCE
from gesturecast.tools.eval.clips import EvalClip
from gesturecast.tools.eval.generate import Generated, generate_offline


@dataclass(frozen=True)
class StyleRequest:
    style: StylePrompt
    guidance: float
    part_styles: PartStyles = ()
    seed: int = 0


def label(style: str, guidance: float, seed: int = 0) -> StyleRequest:
    return StyleRequest(StylePrompt("label", style), guidance, seed=seed)


@dataclass
class StudyRuns:
    bundle: ModelBundle
    clip: EvalClip  # the speech every style is generated on
    sampler: SamplerConfig
    audio_guidance: float = DEFAULT_AUDIO_GUIDANCE  # s_a of every generation
    results: dict[tuple[str, StyleRequest], Generated] = field(default_factory=dict)

    def generate(self, request: StyleRequest, clip: EvalClip | None = None) -> Generated:
        """The motion for ``request`` on ``clip`` (default: the study's clip), generated at most once."""
        clip = self.clip if clip is None else clip
        key = (clip.name, request)
        if key not in self.results:
            self.results[key] = generate_offline(
                self.bundle, self.sampler, clip, request.style, request.seed, self.audio_guidance,
                guidance=request.guidance, part_styles=request.part_styles, stylize=False)
        return self.results[key]

    def real_time_factor(self, request: StyleRequest) -> float:
        """Wall seconds per generated second of a fresh generation of ``request``, session setup excluded."""
        started = time.perf_counter()
        generated = generate_offline(self.bundle, self.sampler, self.clip, request.style, request.seed,
                                     self.audio_guidance, guidance=request.guidance, part_styles=request.part_styles,
                                     stylize=False)
        return (time.perf_counter() - started - generated.setup_s) / self.clip.seconds

    def denoiser_rows(self, request: StyleRequest) -> int:
        """Rows of the batched denoiser call that ``request`` needs (style rows, null style, audio-null)."""
        settings = GeneratorSettings(self.sampler, request.guidance, request.style, threads=1,
                                     audio_guidance=self.audio_guidance, part_styles=request.part_styles)
        return Generator(self.bundle, settings).layout.batch
