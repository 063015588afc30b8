"""Generated motion for evaluation, through the product's own session (the `generate` / `live` paths).

Offline: the session fed by :class:`FastFileSource` (``run_offline``), exactly as ``gesturecast generate``.
Both build their session from the product's :class:`Settings` (:func:`eval_settings`), as every door does.
Live: the same audio replayed at real-time pace in microphone-sized chunks by :class:`LiveEngine`,
its frames released by the scheduler — on a :class:`FakeClock`, so the pacing costs no wall time.
"""

from __future__ import annotations

import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import soundfile

from gesturecast.frames import PoseFrame
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.generator.style_prompt import PartStyles, StylePrompt
from gesturecast.models.motion.skeleton import NUM_JOINTS
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.realtime.audio.sources import FastFileSource, PacedFileSource
from gesturecast.realtime.engine_cli import frames_to_motion
from gesturecast.realtime.generation.generator import Generator
from gesturecast.realtime.gestures.repertoire import GestureRepertoire, load_repertoire
from gesturecast.realtime.pose.session import GestureSession
from gesturecast.realtime.pose.style_hearing import StyleHearing
from gesturecast.realtime.run.engine import LiveEngine, run_offline
from gesturecast.realtime.run.engine_setup import SessionFactory, generator_settings
from gesturecast.realtime.timing.clock import FakeClock
from gesturecast.settings import DEFAULT_AUDIO_GUIDANCE, GENERATOR_STYLE, Settings
from gesturecast.tools.eval.clips import EvalClip

LIVE_CHUNK_SAMPLES = 160  # 10 ms, a typical microphone callback (the offline path reads 512)
# the bundle whose repertoires :func:`_repertoire` holds, and those by what they depend on
_REPERTOIRES = SimpleNamespace(bundle=None, by_key={})


@dataclass(frozen=True)
class SystemSpec:
    name: str
    sampler: SamplerConfig


@dataclass(frozen=True)
class Generated:
    positions: np.ndarray  # (T, J, 3)
    compute_s: float  # wall time spent generating, session setup included
    rotations: np.ndarray  # (T, J, 4) local XYZW rotations of the body joints
    setup_s: float = 0.0  # the part of compute_s spent building the session (ONNX graphs, style embeddings)
    face: np.ndarray | None = None  # (T, 8) blink and expression weights (FACE_NAMES order), None with the face off


def style_settings(style: str | StylePrompt) -> dict:
    """The :class:`Settings` fields that ask for ``style``: a label (or ``text:``/``motion:`` prompt string), or a
    :class:`StylePrompt` of any kind."""
    if isinstance(style, str):
        return {"style": style}
    return {"label": {"style": style.value}, "text": {"prompt": style.value},
            "motion": {"motion_prompt": Path(style.value)}}[style.kind]


def eval_settings(bundle: ModelBundle, sampler: SamplerConfig, style: str | StylePrompt, seed: int,
                  audio_guidance: float = DEFAULT_AUDIO_GUIDANCE, lookahead: int | None = None,
                  guidance: float | None = None, part_styles: PartStyles = (),
                  generator_style: str = GENERATOR_STYLE) -> Settings:
    """The product's :class:`Settings` with what a benchmark varies; every other field at its default (one thread)."""
    steps = sampler.steps if sampler.kind == "ddim" else None
    return Settings(model=bundle.directory, sampler=sampler.kind, steps=steps, seed=seed, audio_guidance=audio_guidance,
                    lookahead=lookahead, guidance=guidance, part_styles=part_styles, generator_style=generator_style,
                    threads=1, **style_settings(style))


def _repertoire(bundle: ModelBundle, settings: Settings) -> GestureRepertoire:
    """The gesture repertoire of ``settings`` on ``bundle``, encoded once per lexicon, style label, seed and threads
    (what it depends on) in this process: a benchmark's many runs share it as a server's streams do."""
    prompt = settings.style_prompt()
    key = (settings.gestures, prompt.value if prompt.kind == "label" else None, settings.seed, settings.threads)
    if _REPERTOIRES.bundle is not bundle:  # the repertoires of one bundle are kept: the one a benchmark runs
        _REPERTOIRES.bundle, _REPERTOIRES.by_key = bundle, {}
    if key not in _REPERTOIRES.by_key:
        _REPERTOIRES.by_key[key] = load_repertoire(settings, bundle)
    return _REPERTOIRES.by_key[key]


def _session(bundle: ModelBundle, settings: Settings, clock: FakeClock, stylize: bool = True) -> GestureSession:
    """The session ``gesturecast generate`` builds from ``settings`` (:class:`SessionFactory`), on a fake clock;
    ``stylize`` False leaves the stylizer out and lets the generator hear the style instead (as before the stylizer)."""
    factory = SessionFactory(settings, bundle, _repertoire(bundle, settings))
    if stylize:
        return factory.session(clock)
    heard = generator_settings(settings, bundle, factory.budget(), StyleHearing())  # every style as asked
    return GestureSession(bundle, Generator(bundle, heard), factory.budget(), clock,
                          replace(factory.config, style_params=None, hearing=StyleHearing()))


def _generated(frames: list[PoseFrame], start: float, setup_s: float) -> Generated:
    ordered = sorted(frames, key=lambda f: f.seq)
    motion = frames_to_motion(ordered)  # 52 joints: body + fingers
    positions = motion.positions()[:, :NUM_JOINTS]  # (T, 22, 3): the metrics and evaluation networks see the body
    face = np.stack([f.face for f in ordered]) if ordered and ordered[0].face is not None else None  # (T, 8)
    return Generated(positions, time.perf_counter() - start, motion.rotations[:, :NUM_JOINTS], setup_s, face)


def _with_wav(audio: np.ndarray, run):
    with tempfile.TemporaryDirectory(prefix="gesturecast-eval-") as folder:
        path = Path(folder) / "speech.wav"
        soundfile.write(path, audio, SAMPLE_RATE, subtype="FLOAT")
        return run(path)


def generate_offline(
    bundle: ModelBundle, sampler: SamplerConfig, clip: EvalClip, style: str | StylePrompt, seed: int = 0,
    audio_guidance: float = DEFAULT_AUDIO_GUIDANCE, lookahead: int | None = None, guidance: float | None = None,
    part_styles: PartStyles = (), stylize: bool = True, generator_style: str = GENERATOR_STYLE,
) -> Generated:
    """Motion for the clip's audio in ``style`` through ``run_offline`` (the `generate` path, the product's settings
    of :func:`eval_settings`), at look-ahead ``lookahead`` (default: the model's δa) and style guidance ``guidance``
    (default: the model's); body parts named in ``part_styles`` follow their own prompt; the generator hears
    ``generator_style`` under the stylizer's styles; ``stylize`` False: the generator's motion without the stylizer
    after it."""
    start = time.perf_counter()
    settings = eval_settings(bundle, sampler, style, seed, audio_guidance, lookahead, guidance, part_styles,
                             generator_style)
    session = _session(bundle, settings, FakeClock(), stylize)
    setup_s = time.perf_counter() - start
    frames, _ = _with_wav(clip.audio, lambda path: run_offline(session, FastFileSource(path)))
    return _generated(frames, start, setup_s)


def generate_live(
    bundle: ModelBundle, sampler: SamplerConfig, clip: EvalClip, style: str, seed: int = 0,
    generator_style: str = GENERATOR_STYLE,
) -> Generated:
    """Motion for the clip's audio through :class:`LiveEngine` (paced source, scheduler, sink), with the settings of
    :func:`eval_settings`."""
    start = time.perf_counter()
    clock = FakeClock()
    session = _session(bundle, eval_settings(bundle, sampler, style, seed, generator_style=generator_style), clock)
    setup_s = time.perf_counter() - start
    received: list[PoseFrame] = []

    def run(path: Path) -> None:
        source = PacedFileSource(path, chunk_samples=LIVE_CHUNK_SAMPLES, clock=clock)
        LiveEngine(session, source, received.append, clock).run()

    _with_wav(clip.audio, run)
    return _generated(received, start, setup_s)
