"""``bench styles``'s ``stylizer`` section: can a viewer tell the styles apart, and what does it cost the speech?

Held-out speech (speech with no motion anywhere in the training data: ZeroEGGS 037 "Flirty", the first
``seconds``), each of :data:`JUDGED_STYLES` with every seed, at the default settings, with the stylizer
(``styled``) and, for comparison, without it (``generator``: the motion the generator alone gives, as before the
stylizer existed). Per variant:

- ``fk``: the forward-kinematics measure of ``gesturecast.models.style.descriptors`` (wrist speed, wrist height,
  hand spread, forward lean, stance, tempo, head pitch; body heights, radians, 1/s): every pair of styles' distance
  (mean over seeds), the closest pair, and the seed floor (mean over styles of the distance between two seeds of
  one style); ``min_over_floor`` = closest pair / seed floor;
- ``judge``: the style judge (``gesturecast.models.style.judge``) on each seed's set of clips: per-style share of
  windows judged as the style asked for, and their mean; ``classifier``: the same with the frozen classifier of
  ``gesturecast eval`` (kept for continuity; it knows 16 labels);
- ``following``: the ``bench voices`` measure (best correlation of upper-body speed with speech energy within
  ±0.5 s) per style, mean over seeds, and its ratio to the product's default's (``Settings()``: the default style
  through the stylizer, the generator hearing its generator style);
- ``jerk``: GENEA jerk of root-relative positions (m/s³) per style, and as a ratio to real motion capture of the
  same voice (ZeroEGGS 067, the whole take);
- ``face``: per style, the expression weight's correlation with speech energy (dB, per frame), its standard
  deviation over time, and blinks per minute.

``judge_voices`` (:mod:`.judge_voices`; left out with ``--quick``): the judge on the held-out voices of ``bench
voices`` as well, per group and pooled.

``--grid OUT.png`` draws the styled clips of the first seed, a row per style, at :data:`GRID_TIMES` (front and side
of each frame), and ``OUT_generator.png`` the same without the stylizer.

``cost``: the stylizer's own time on the styled frames of one stream (four frames at a time, as the session builds
them), per second of motion, and ``cpu_increase``: that time over the rest of the stream's generation time (the
stylizer adds no latency: it works on each frame as it is built, with no look-ahead).
"""

from __future__ import annotations

import itertools
import time
from pathlib import Path

import numpy as np

from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.evaluation.metrics import jerk, root_relative
from gesturecast.models.evaluation.speech_following import frame_energy_db, speech_following
from gesturecast.models.evaluation.style_classifier import StyleClassifier
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.models.motion.retarget import load_motion_file
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.models.style.descriptors import FK_MEASURE, clip_descriptor, style_distance
from gesturecast.models.style.judge import JUDGED_STYLES, StyleJudge
from gesturecast.models.style.params import DEFAULT_STYLE_PARAMS
from gesturecast.realtime.pose.face import BLINK_SHAPES
from gesturecast.realtime.pose.stylizer import Stylizer
from gesturecast.settings import Settings
from gesturecast.tools.bench.styles.judge_voices import accuracy, judge_on_voices, judged_windows, scores
from gesturecast.tools.eval.clips import EvalClip
from gesturecast.tools.eval.generate import Generated, generate_offline

HELD_OUT_SPEECH = "zeggs/037_Flirty_1_x_1_0.wav"
REAL_MOTION = "zeggs/067_Speech_2_x_1_0.bvh"
DEFAULT_JUDGE = DEFAULT_STYLE_PARAMS.parent / "judge.json"
CLOSED = 0.5  # lid closure that counts as a blink
DEFAULT_STYLE = Settings().style  # following is measured against the product's default motion (a judged style)
GRID_TIMES = (8.0, 20.0, 32.0, 44.0, 56.0)  # seconds of the grid's columns (those past the clip are left out)
Clips = dict[tuple[str, int], Generated]


def held_out_speech(data: Path, seconds: float) -> EvalClip:
    audio = load_audio(data / HELD_OUT_SPEECH)[: int(seconds * SAMPLE_RATE)]
    return EvalClip("zeggs/037_Flirty_1[speech only]", audio, DEFAULT_STYLE)


def _generate(bundle: ModelBundle, clip: EvalClip, seeds: tuple[int, ...], stylize: bool) -> Clips:
    sampler = SamplerConfig("ddim", bundle.default_steps)
    return {(style, seed): generate_offline(bundle, sampler, clip, style, seed, stylize=stylize)
            for style in JUDGED_STYLES for seed in seeds}


def _descriptor(generated: Generated) -> np.ndarray:
    root = generated.positions[:, 0]  # (T, 3) the hips
    return clip_descriptor(generated.rotations, root, MOTION_FPS)


def fk_section(clips: Clips, seeds: tuple[int, ...]) -> dict:
    descriptors = {key: _descriptor(generated) for key, generated in clips.items()}
    pairs = {f"{a}-{b}": float(np.mean([style_distance(descriptors[(a, s)], descriptors[(b, s)]) for s in seeds]))
             for a, b in itertools.combinations(JUDGED_STYLES, 2)}
    floors = {style: float(np.mean([style_distance(descriptors[(style, a)], descriptors[(style, b)])
                                    for a, b in itertools.combinations(seeds, 2)])) for style in JUDGED_STYLES}
    floor = float(np.mean(list(floors.values())))
    closest = min(pairs, key=pairs.get)
    return {"measure": list(FK_MEASURE), "pairs": _rounded(pairs), "closest_pair": closest,
            "closest": round(pairs[closest], 3), "seed_floor": round(floor, 3),
            "seed_floor_per_style": _rounded(floors),
            "min_over_floor": round(pairs[closest] / max(floor, 1e-9), 2),
            "descriptors": {style: np.round(descriptors[(style, seeds[0])], 3).tolist() for style in JUDGED_STYLES}}


def judge_section(clips: Clips, seeds: tuple[int, ...], judge: StyleJudge) -> dict:
    return accuracy(judged_windows(clips, seeds, judge))


def classifier_section(clips: Clips, seeds: tuple[int, ...], classifier: StyleClassifier) -> dict:
    per_style = {style: float(np.mean([classifier.accuracy([clips[(style, seed)].positions], style)
                                       for seed in seeds])) for style in JUDGED_STYLES}
    return {**scores(per_style), "labels": len(classifier.labels)}


def mean_following(clips: Clips, style: str, seeds: tuple[int, ...], audio: np.ndarray) -> float:
    return float(np.mean([speech_following(clips[(style, seed)].positions, audio, SAMPLE_RATE,
                                           MOTION_FPS).best_correlation for seed in seeds]))


def following_section(clips: Clips, seeds: tuple[int, ...], audio: np.ndarray, baseline: Clips) -> dict:
    """Each style's following and its ratio to the default style's in the ``baseline`` clips (the product's)."""
    per_style = {style: mean_following(clips, style, seeds, audio) for style in JUDGED_STYLES}
    default = mean_following(baseline, DEFAULT_STYLE, seeds, audio)
    ratios = {style: value / default for style, value in per_style.items()}
    return {"per_style": _rounded(per_style), "baseline": {"settings": "Settings()", "following": round(default, 3)},
            "ratio_to_default": _rounded(ratios), "min_ratio": round(min(ratios.values()), 3)}


def real_jerk(data: Path) -> float:
    motion = load_motion_file(data / REAL_MOTION)
    _, positions = CANONICAL.forward_kinematics(motion.rotations, motion.root_position)
    return jerk(root_relative(positions), MOTION_FPS)


def jerk_section(clips: Clips, seeds: tuple[int, ...], real: float) -> dict:
    per_style = {style: float(np.mean([jerk(root_relative(clips[(style, seed)].positions), MOTION_FPS)
                                       for seed in seeds])) for style in JUDGED_STYLES}
    ratios = {style: value / real for style, value in per_style.items()}
    return {"per_style": _rounded(per_style), "real": round(real, 1), "ratio_to_real": _rounded(ratios),
            "max_ratio": round(max(ratios.values()), 3)}


def face_section(clips: Clips, seeds: tuple[int, ...], audio: np.ndarray) -> dict:
    out = {}
    for style in JUDGED_STYLES:
        rows = []
        for seed in seeds:
            face = clips[(style, seed)].face  # (T, 8)
            energy = frame_energy_db(audio, SAMPLE_RATE, MOTION_FPS, len(face), -60.0)  # (T,)
            expression = face[:, BLINK_SHAPES:].max(axis=1)  # (T,) the strongest preset
            correlation = np.corrcoef(expression, energy)[0, 1] if expression.std() > 0 else 0.0
            closing = np.diff((face[:, 0] > CLOSED).astype(int)) == 1
            rows.append((correlation, expression.std(), closing.sum() * 60.0 * MOTION_FPS / len(face)))
        correlation, spread, blinks = np.mean(rows, axis=0)
        out[style] = {"energy_correlation": round(float(correlation), 3), "expression_sd": round(float(spread), 3),
                      "blinks_per_min": round(float(blinks), 1)}
    return out


def stylizer_cost(bundle: ModelBundle, generated: Generated, style: str) -> dict:
    """The stylizer's time on one stream's frames (``style``), per motion second and as a share of generation."""
    from gesturecast.realtime.generation.generator import Generator, GeneratorSettings

    resolver = Generator(bundle, GeneratorSettings(SamplerConfig("ddim", 4))).styles
    stylizer = Stylizer.from_file(DEFAULT_STYLE_PARAMS, resolver.embed, MOTION_FPS)
    stylizer.set_style(stylizer.target(StylePrompt("label", style), None, 1.0, (), 1.0), 0.0)
    times = np.arange(len(generated.rotations)) / MOTION_FPS
    started = time.perf_counter()
    for start in range(0, len(times), 4):  # one latent's frames at a time, as the session builds them
        stylizer.apply(generated.rotations[start:start + 4], times[start:start + 4])
    spent = time.perf_counter() - started
    generation = generated.compute_s - generated.setup_s
    return {"ms_per_motion_second": round(1e3 * spent / times[-1], 3), "generation_s": round(generation, 2),
            "cpu_increase": round(spent / max(generation - spent, 1e-9), 4)}


def style_grid(clips: Clips, seed: int, out_path: Path) -> Path:
    """A row per judged style of its clip with ``seed``, drawn at GRID_TIMES (front and side)."""
    from gesturecast.files import atomic_file
    from gesturecast.tools.render.animation import contact_sheet
    from gesturecast.tools.render.compare import CompareRow, draw_row
    from gesturecast.tools.render.stick_figure import FigureConfig

    frames = min(len(clips[(style, seed)].positions) for style in JUDGED_STYLES)
    indices = [int(t * MOTION_FPS) for t in GRID_TIMES if t * MOTION_FPS < frames]
    images = [image for style in JUDGED_STYLES for image in draw_row(
        CompareRow(style, clips[(style, seed)].positions, CANONICAL.parents, CANONICAL.names), indices, MOTION_FPS,
        0.0, FigureConfig())]
    with atomic_file(out_path, binary=True) as handle:
        contact_sheet(images, len(indices)).save(handle, format="PNG")
    return out_path


def stylizer_report(bundle: ModelBundle, data: Path, seconds: float, seeds: tuple[int, ...],
                    grid: Path | None = None, voices: bool = True) -> dict:
    """The whole section (module docstring); ``voices``: also the judge on the held-out voices
    (:mod:`.judge_voices`)."""
    clip = held_out_speech(data, seconds)
    judge, classifier, real = StyleJudge.load(DEFAULT_JUDGE), StyleClassifier.load(), real_jerk(data)
    report = {"speech": {"clip": clip.name, "seconds": round(clip.seconds, 2), "seeds": list(seeds)},
              "styles": list(JUDGED_STYLES)}
    variants = {variant: _generate(bundle, clip, seeds, stylize)
                for variant, stylize in (("generator", False), ("styled", True))}
    for variant, clips in variants.items():  # the styled default's clips are the product's: the following baseline
        stylize = variant == "styled"
        if grid is not None:
            path = grid if stylize else grid.with_name(f"{grid.stem}_generator{grid.suffix}")
            report.setdefault("grid", []).append(str(style_grid(clips, seeds[0], path)))
        report[variant] = {"fk": fk_section(clips, seeds), "judge": judge_section(clips, seeds, judge),
                           "classifier": classifier_section(clips, seeds, classifier),
                           "following": following_section(clips, seeds, clip.audio, variants["styled"]),
                           "jerk": jerk_section(clips, seeds, real)}
    styled = variants["styled"]
    if voices:
        report["judge_voices"] = judge_on_voices(bundle, data, seeds, judge, lambda *a: _generate(*a, stylize=True),
                                                 judged_windows(styled, seeds, judge))
    report["face"] = face_section(styled, seeds, clip.audio)
    report["cost"] = stylizer_cost(bundle, styled[("angry", seeds[0])], "angry")
    return report


def _rounded(values: dict[str, float]) -> dict[str, float]:
    return {key: round(value, 3) for key, value in values.items()}
