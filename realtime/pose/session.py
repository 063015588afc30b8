"""One stream's state and the step that turns audio into poses: the shared core of `live` and `generate`.

Data flow (docs/architecture.md, "Data flow"): pushed chunks wait in a short pending list until the audio up to
``(i+1)·d + δ`` (latent ``i``'s window end at the generator's look-ahead δ, docs/latency.md) has
arrived; then, in one burst, streaming features of
the pending audio → normalised feature buffer → one generator step for latent ``i`` (K-step DDIM or
DDPM, KV cache, CFG) → d motion-feature frames → root integration + 6D → quaternions → idle
cross-fade in silence → the stylizer (the style's posture, amplitude, tempo: :mod:`gesturecast.realtime.pose.stylizer`)
→ the gesture size (``intensity``, ``pause``: :mod:`gesturecast.realtime.pose.gesture_size`)
→ procedural fingers (:mod:`gesturecast.realtime.pose.hands`) → :class:`PoseFrame` with
capture and presentation times, and the speaking flag and viseme weights of the frame's own audio instant
(:mod:`gesturecast.models.audio.vad`, :mod:`gesturecast.models.audio.lipsync`, computed by the feature extractor
in the same burst). The idle cross-fade decides per latent with look-ahead and a silence hold
(:meth:`GestureSession._gesturing`); the frame's ``speaking`` flag is not that decision but the voice-activity
flag of the frame's own audio (its 267 ms hangover included), so it matches the visemes. Computing the
features in that burst instead of per chunk gives the same bits (the extractor is chunk-size
invariant) with a quarter of the wake-ups, each on warm caches.

The session never reads a clock: every time it uses is stream time (frame index / fps) or the
capture time carried by the audio chunks, so a file replayed at real-time pace and the same file
processed as fast as possible give identical poses (the parity the tests check).
"""

from __future__ import annotations

import logging
import math
from collections import deque
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np

from gesturecast.frames import VISEME_NAMES, PoseFrame
from gesturecast.models.audio.dsp import frame_boundary, frames_complete
from gesturecast.models.audio.lipsync import LipSyncConfig
from gesturecast.models.audio.streaming import StreamingFeatureExtractor, speaking_flags
from gesturecast.models.generator.denoiser_config import audio_window_bounds, audio_window_end
from gesturecast.models.generator.style_prompt import PartStyles, StylePrompt
from gesturecast.models.motion.motion_features import features_to_rotations
from gesturecast.models.motion.root_anchor import RootAnchor, RootMode, RootTravel
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.models.style.params import DEFAULT_STYLE_PARAMS
from gesturecast.realtime.audio.sources import AudioChunk
from gesturecast.realtime.generation.generator import Generator
from gesturecast.realtime.gestures.director import GestureDirector
from gesturecast.realtime.gestures.repertoire import GestureRepertoire
from gesturecast.realtime.pose.face import Expressions, FaceAnimator, text_embedder
from gesturecast.realtime.pose.feature_buffer import FeatureBuffer
from gesturecast.realtime.pose.gesture_size import FULL_SIZE, GestureSize
from gesturecast.realtime.pose.hands import HandPose
from gesturecast.realtime.pose.idle import IdleMotion
from gesturecast.realtime.pose.motion_smoother import MotionSmoother
from gesturecast.realtime.pose.seed_motion import SeedMotion
from gesturecast.realtime.pose.session_controls import SessionControls
from gesturecast.realtime.pose.style_hearing import StyleHearing, StyleState
from gesturecast.realtime.pose.stylizer import Stylizer
from gesturecast.realtime.pose.transitions import PoseCrossfade
from gesturecast.realtime.timing.clock import Clock
from gesturecast.realtime.timing.latency import LatencyBudget, LatencyStats
from gesturecast.settings import FACE_FULL, FACE_OFF, face_names

logger = logging.getLogger(__name__)

STAGE_FEATURES = "features"
STAGE_DENOISER = "denoiser"
STAGE_DECODER = "decoder"
STAGE_POSES = "poses"  # gesture blend, smoothing, root, rotations, cross-fades, hands: decoded features → PoseFrames
SPEECH = 1.0  # cross-fade weight of the generated stream while speaking (idle = 0)
IDLE = 0.0


class PoseStyle(NamedTuple):
    """The style in effect when a latent was generated, as its pose frames show it: the description they name, the
    face's expression mix (x̂0 = γ·D(style) + (1 − γ)·D(second_style)) and the gesture size (0 while paused)."""

    description: str
    style: StylePrompt
    second_style: StylePrompt | None
    gamma: float
    part_styles: PartStyles = ()
    strength: float = 1.0
    gesture_size: float = FULL_SIZE


@dataclass(frozen=True)
class SessionConfig:
    idle_fade_s: float = 0.6  # cross-fade duration between idle motion and speech gestures
    silence_hold_s: float = 1.0  # silence this long after the last speech frame fades to idle
    root_mode: RootMode = RootMode.BOUNDED  # in place by default (models/motion/root_anchor.py)
    seed_motion: SeedMotion | None = None  # start from this motion's last pose, not idle (realtime/pose/seed_motion.py)
    lipsync: str = "vrm0"  # a key of VISEME_NAMES: fill PoseFrame.visemes (docs/lipsync.md); "off": None
    face: str = FACE_FULL  # blinks and expression in PoseFrame.face ("blink": blinks only; "off": None)
    style_params: Path | None = DEFAULT_STYLE_PARAMS  # the stylizer's styles (realtime/pose/stylizer.py); None: off
    intensity: float = FULL_SIZE  # gesture size 0..2 around the idle pose (realtime/pose/gesture_size.py)
    paused: bool = False  # the body in the idle pose until a pause control says otherwise
    style: StyleState | None = None  # the stream's style, from Settings (None: what the generator was made with)
    hearing: StyleHearing | None = None  # what the generator hears of it (None: every style as asked)


class GestureSession:
    """Audio chunks in, timed pose frames out, for one stream (constant memory on any duration). ``gestures``: the
    stream's gestures, which every door's words and gesture controls reach (none by default)."""

    def __init__(
        self,
        bundle: ModelBundle,
        generator: Generator,
        budget: LatencyBudget,
        clock: Clock,
        config: SessionConfig | None = None,
        stats: LatencyStats | None = None,
        gestures: GestureDirector | None = None,
    ) -> None:
        self.bundle = bundle
        self.generator = generator
        self.budget = budget
        self.config = config or SessionConfig()
        self.stats = stats or LatencyStats(clock)
        self.denoiser_config = generator.audio_config  # the audio layout at the generator's look-ahead δ
        self.fps = bundle.feature_config.fps
        self.sample_rate = bundle.feature_config.sample_rate
        self.extractor = StreamingFeatureExtractor(bundle.feature_config,
                                                   LipSyncConfig() if self.lipsync_on else None)
        self.idle = IdleMotion(seed=generator.settings.seed)
        self._hold_frames = round(self.config.silence_hold_s * self.fps)
        self.root = RootAnchor(self.config.root_mode, fps=self.fps)
        self.gestures = gestures or GestureDirector(
            GestureRepertoire(), self.denoiser_config.frames_per_latent / self.fps, budget.total_s)
        self.controls = SessionControls(generator, self.root, self.gestures, self.config.intensity, self.config.paused,
                                        style=self.config.style, hearing=self.config.hearing)
        self.smoother = MotionSmoother(budget.smoothing_frames)
        self.hands = HandPose(self.fps, seed=generator.settings.seed)
        self.face = None if self.config.face == FACE_OFF else FaceAnimator(
            self.config.face, generator.settings.seed, Expressions(text_embedder(generator.styles)))
        self.stylizer = None if self.config.style_params is None else Stylizer.from_file(
            self.config.style_params, generator.styles.embed, self.fps)
        self.reset()

    @property
    def lipsync_on(self) -> bool:
        return self.config.lipsync in VISEME_NAMES

    @property
    def viseme_names(self) -> tuple[str, ...]:
        """Blend-shape names of the frames' viseme weights (VRM 0.x or 1.0), () with lip sync off."""
        return VISEME_NAMES.get(self.config.lipsync, ())

    @property
    def face_names(self) -> tuple[str, ...]:
        """Blend-shape names of the frames' face weights (blinks, emotion presets), () with the face off."""
        return face_names(self.config.face, self.config.lipsync)

    def reset(self) -> None:
        """Forget the stream (features, generator history, root anchor, idle fade): the next chunk is sample 0.
        With a seed motion the generator's history holds it again and the first pose is its last one."""
        self.extractor.reset()
        self.features = FeatureBuffer(self.extractor.num_features)
        seed = self.config.seed_motion
        self.generator.reset(seed_pose=None if seed is None else seed.features)
        self.seed_fade = None if seed is None else PoseCrossfade(self.config.idle_fade_s, initial_weight_b=IDLE)
        if self.seed_fade is not None:
            self.seed_fade.fade_to(SPEECH, 0.0)  # from the seed's pose at t = 0 into the stream
        self.root.reset()
        self.travel = RootTravel()  # the root's distance, travel and facing from the start (the run's summary)
        self.smoother.reset()
        self.hands.reset()
        if self.face is not None:
            self.face.reset()
        if self.stylizer is not None:
            self.stylizer.reset()
        self._unsmoothed: deque[tuple[int, bool, str]] = deque()  # (frame, gesturing, gesture) inside the smoother
        self.gestures.reset()
        self._visemes: deque[np.ndarray] = deque()  # (5,) weights of the audio frames not yet posed, in order
        self._speaking: deque[bool] = deque()  # voice-activity flag of the audio frames not yet posed, in order
        self._energy: deque[float] = deque()  # speech energy (dB) of the audio frames not yet posed, in order
        self.crossfade = PoseCrossfade(self.config.idle_fade_s, initial_weight_b=IDLE)
        self.gesture_size = GestureSize(self.idle, self.controls.gesture_size)
        self.next_latent = 0
        self.frames_out = 0
        self.samples_in = 0
        self._pending_audio: list[np.ndarray] = []  # chunks since the last feature burst (< one latent of audio)
        self._anchor = (0, 0.0)  # (stream sample, capture time) of the newest chunk
        self._last_capture = -math.inf  # capture time given to the newest frame (frame times never go back)
        self._last_speech_frame = -math.inf
        self._frame_limit: int | None = None
        self.nonfinite_poses = 0  # generated poses with NaN/inf, replaced by the last good pose
        self._last_good: tuple[np.ndarray, np.ndarray] | None = None  # (J, 4) rotations, (3,) root

    # ---- audio in ----
    def push(self, chunk: AudioChunk) -> list[PoseFrame]:
        """Feed one chunk; returns the pose frames it completed (often none)."""
        self._anchor = (chunk.start_sample, chunk.capture_time)
        self.samples_in = chunk.start_sample + len(chunk.samples)
        self.gestures.heard(self.samples_in / self.sample_rate, chunk.samples)
        self._pending_audio.append(chunk.samples)
        if self.samples_in < self._samples_needed(self.next_latent):
            return []
        self._extract_pending()
        return self._generate_ready()

    def _samples_needed(self, latent: int) -> int:
        """Stream samples after which every audio frame of ``latent``'s window is complete."""
        return int(frame_boundary(audio_window_end(latent, self.denoiser_config), self.sample_rate, self.fps))

    def _extract_pending(self) -> None:
        if not self._pending_audio:
            return
        samples = np.concatenate(self._pending_audio)
        self._pending_audio.clear()
        with self.stats.time(STAGE_FEATURES):
            raw = self.extractor.push(samples)  # (n, F)
        speaking = speaking_flags(raw, self.bundle.feature_config)  # (n,) one per new audio frame
        self.features.append(self.bundle.audio_stats.apply(raw), speaking)
        self._speaking.extend(speaking.tolist())
        self._energy.extend(raw[:, self.bundle.feature_config.layout["energy"]][:, 0].tolist())
        if self.lipsync_on:
            self._visemes.extend(self.extractor.take_visemes())  # one (5,) row per new audio frame

    def finish(self) -> list[PoseFrame]:
        """End of stream: pad with silence for the look-ahead so every captured audio frame gets a pose (the words
        still waiting for what follows them are decided first)."""
        self.gestures.end_of_words()
        self._extract_pending()
        audio_frames = self.extractor.frames_emitted
        if audio_frames == 0:
            return []
        padding = self._samples_until_generated(audio_frames - 1)
        self._frame_limit = audio_frames
        start, time = self._anchor
        pad_time = time + (self.samples_in - start) / self.sample_rate
        frames = self.push(AudioChunk(np.zeros(padding, np.float32), self.samples_in, pad_time))
        with self.stats.time(STAGE_POSES):
            return frames + self._pose_frames(self.smoother.flush(self.bundle.motion_feature_dim), self._pose_style())

    def silence_to_flush(self) -> int:
        """Samples of silence that, pushed after the audio so far, bring out the pose of its every frame without ending
        the stream: the look-ahead of the latent holding its last frame and the smoothing window after that frame
        (the silence becomes part of the stream; its own poses come out too)."""
        audio_frames = frames_complete(self.samples_in, self.sample_rate, self.fps)
        if audio_frames == 0:
            return 0
        return self._samples_until_generated(audio_frames - 1 + self.smoother.half_width)

    def _samples_until_generated(self, frame: int) -> int:
        """Samples still to push until the latent holding ``frame`` can be generated (0 when it can now)."""
        latent = frame // self.denoiser_config.frames_per_latent
        needed = audio_window_end(latent, self.denoiser_config)
        return max(int(frame_boundary(needed, self.sample_rate, self.fps)) - self.samples_in, 0)

    # ---- generation ----
    def _generate_ready(self) -> list[PoseFrame]:
        """Every latent the features allow; their poses built in one batch per run of latents with the same style
        (a live chunk brings one latent at most; ``generate``'s one-second chunks bring several)."""
        frames: list[PoseFrame] = []
        batch: list[np.ndarray] = []  # smoothed rows (m, D) of the latents since the last build
        batch_style = None
        ready = range(self.next_latent, self._latents_ready())
        if len(ready) > 1:  # a one-second push: their conditions in one call
            self.generator.prepare([self.features.window(index, self.denoiser_config) for index in ready], True)
        for index in ready:
            smoothed = self._generate_latent(index)  # (m, D)
            style = self._pose_style()
            if batch and style != batch_style:
                frames.extend(self._built_poses(batch, batch_style))
                batch = []
            batch.append(smoothed)
            batch_style = style
            self.next_latent = index + 1
            self.features.forget_before(audio_window_bounds(self.next_latent, self.denoiser_config)[0])
        return frames + self._built_poses(batch, batch_style)

    def _latents_ready(self) -> int:
        """One past the last latent whose audio window the features complete (``audio_window_end`` ≤ their end)."""
        return (self.features.end - self.denoiser_config.audio_lookahead) // self.denoiser_config.frames_per_latent

    def _pose_style(self) -> PoseStyle:
        """What the pose frames of the latent just generated take from the style in effect."""
        style = self.controls.style
        return PoseStyle(self.controls.describe(), style.style, style.second_style, style.gamma, style.part_styles,
                         style.strength, self.controls.gesture_size)

    def _built_poses(self, batch: list[np.ndarray], style: PoseStyle) -> list[PoseFrame]:
        """The pose frames of the smoothed rows of a run of latents (list of (m, D)) in ``style``, in order."""
        if not batch:
            return []
        with self.stats.time(STAGE_POSES):
            return self._pose_frames(np.concatenate(batch), style)

    def _generate_latent(self, index: int) -> np.ndarray:
        """Latent ``index`` denoised and decoded; returns the smoothed motion rows (m, D) it pushed out."""
        d = self.denoiser_config.frames_per_latent
        self.controls.advance(index * d / self.fps)
        window = self.features.window(index, self.denoiser_config)  # (A', F)
        imposed = self.gestures.play(index)
        with self.stats.time(STAGE_DENOISER):
            latent = self.generator.denoise(window, True, None if imposed is None else (imposed.target,
                                                                                       imposed.weights))  # (C,)
        with self.stats.time(STAGE_DECODER):
            motion = self.generator.decode(latent)  # (d, D)
        with self.stats.time(STAGE_POSES):
            if imposed is not None:
                motion = imposed.blend(motion)
            gesture = "" if imposed is None else imposed.names
            gesturing = self._gesturing(index) or bool(gesture)  # a cued gesture shows in silence too
            self._unsmoothed.extend((index * d + j, gesturing, gesture) for j in range(d))
            return self.smoother.push(motion)

    def _pose_frames(self, smoothed: np.ndarray, style: PoseStyle) -> list[PoseFrame]:
        """Pose frames of the rows (m, D) that left the smoother, the oldest frames inside it, in order; built
        per batch (one call per stage for the m rows, the stateful stages stepping frame by frame inside)."""
        rows = [self._unsmoothed.popleft() for _ in range(len(smoothed))]  # (frame, gesturing, gesture)
        speaking = [self._speaking.popleft() for _ in rows]  # each audio frame's voice activity
        energy = [self._energy.popleft() for _ in rows]  # each audio frame's speech energy (dB)
        visemes = [self._visemes.popleft() if self.lipsync_on else None for _ in rows]  # each audio frame's
        wanted = sum(self._wanted(frame) for frame, _, _ in rows)  # a prefix: frames past the end are dropped
        if wanted == 0:
            return []
        frames = np.array([frame for frame, _, _ in rows[:wanted]])  # (n,)
        times = frames / self.fps  # (n,) stream seconds
        bodies, roots = self._finite_poses(frames, smoothed[:wanted], [g for _, g, _ in rows[:wanted]])
        bodies = self._stylized(bodies, times, style)  # (n, J, 4)
        self.gesture_size.set_size(style.gesture_size, float(times[0]))
        bodies, roots = self.gesture_size.apply(bodies, roots, times)  # (n, J, 4), (n, 3)
        rotations = self.hands.extend(bodies, times)  # (n, J + 30, 4) on CANONICAL_WITH_HANDS
        faces = self._faces(times, speaking[:wanted], energy[:wanted], style)  # (n, 8) or None
        return [self._pose_frame(int(frame), rotations[k], roots[k], style.description, rows[k][2], speaking[k],
                                 visemes[k], None if faces is None else faces[k]) for k, frame in enumerate(frames)]

    def _stylized(self, bodies: np.ndarray, times: np.ndarray, style: PoseStyle) -> np.ndarray:
        """(n, J, 4) body rotations re-performed in the style in effect (unchanged with the stylizer off)."""
        if self.stylizer is None:
            return bodies
        self.stylizer.set_style(self.stylizer.target(style.style, style.second_style, style.gamma, style.part_styles,
                                                     style.strength), float(times[0]))
        return self.stylizer.apply(bodies, times)

    def _faces(self, times: np.ndarray, speaking: list[bool], energy: list[float], style: PoseStyle
               ) -> np.ndarray | None:
        """(n, 8) face weights of the frames (the expression of the style in effect, living with the speech's
        emphasis), None with the face off."""
        if self.face is None:
            return None
        expression = self.face.expressions.of(style.style)  # (5,)
        if style.second_style is not None:  # x̂0 = γ·D(c1) + (1 − γ)·D(c2): the faces mix the same way
            second = self.face.expressions.of(style.second_style)
            expression = np.clip(style.gamma * expression + (1.0 - style.gamma) * second, 0.0, 1.0)
        self.face.set_style(expression, float(times[0]), style.style.value if style.style.kind == "label" else None)
        return self.face.frames(times, speaking, energy)

    def _gesturing(self, index: int) -> bool:
        """Whether latent ``index``'s frames fade to speech gestures (else to idle): speech within the hold time
        before this latent or in its look-ahead (only audio it may see). The idle cross-fade's decision, made
        early so the arms are up when the voice starts; not the frames' ``speaking`` flag."""
        previous_end = audio_window_end(index - 1, self.denoiser_config) if index else 0
        last = self.features.last_speech(previous_end, audio_window_end(index, self.denoiser_config))
        if last is not None:
            self._last_speech_frame = last
        return self._last_speech_frame >= index * self.denoiser_config.frames_per_latent - self._hold_frames

    def _wanted(self, frame: int) -> bool:
        return self._frame_limit is None or frame < self._frame_limit

    def _pose_frame(self, frame: int, rotations: np.ndarray, root: np.ndarray, style: str, gesture: str,
                    speaking: bool, visemes: np.ndarray | None, face: np.ndarray | None) -> PoseFrame:
        """The PoseFrame of one pose (rotations (J + 30, 4), root (3,)) in the ``style`` described, flagged
        ``speaking`` by the voice activity of its own audio instant, naming the lexicon ``gesture`` playing ("" for
        none), with its face weights."""
        capture = self._capture_time(frame)
        self.frames_out += 1
        return PoseFrame(
            seq=frame,
            capture_time=capture,
            presentation_time=capture + self.budget.total_s,
            root_position=root,
            rotations=rotations,
            style=style,
            speaking=speaking,
            visemes=visemes,
            gesture=gesture,
            face=face,
        )

    def _finite_poses(self, frames: np.ndarray, features: np.ndarray, gesturing: list[bool]
                      ) -> tuple[np.ndarray, np.ndarray]:
        """(n, J, 4) rotations and (n, 3) roots of feature rows (n, D), cross-faded toward speech or idle by each
        frame's ``gesturing`` flag. A row that is not finite, or gives a pose that is not, becomes the last good pose
        (the idle pose before any), counted and warned about once: no bridge, recorder or JSON writer ever receives a
        NaN or inf."""
        times = frames / self.fps  # (n,)
        finite = np.isfinite(features).all(axis=1)  # (n,) a NaN row never reaches the root integrator
        roots, yaws = self._root_steps(features, finite)  # (n, 3), (n,)
        bodies = np.empty((len(frames), CANONICAL.num_joints, 4))  # (n, J, 4)
        if finite.any():
            bodies[finite] = features_to_rotations(features[finite], yaws[finite])
        for k, t in enumerate(times):
            self.crossfade.fade_to(SPEECH if gesturing[k] else IDLE, t)
            if finite[k]:
                bodies[k], roots[k] = self._faded(t, bodies[k], roots[k])
            if finite[k] and np.isfinite(bodies[k]).all() and np.isfinite(roots[k]).all():
                self._last_good = (bodies[k], roots[k])
            else:
                bodies[k], roots[k] = self._held_pose(int(frames[k]), t)
        return bodies, roots

    def _root_steps(self, features: np.ndarray, finite: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(n, 3) hips positions and (n,) facing yaws of the finite rows (the others: zeros), in stream order."""
        roots, yaws = np.zeros((len(features), 3)), np.zeros(len(features))
        for k in np.flatnonzero(finite):
            roots[k], yaws[k] = self.root.step(features[k])
            self.travel.update(roots[k], yaws[k])
        return roots, yaws

    def _faded(self, t: float, rotations: np.ndarray, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One generated pose ((J, 4), (3,)) cross-faded with idle motion and with the seed motion's last pose."""
        root = position
        if self.crossfade.weight(t) < SPEECH:  # idle visible: blend (skipped while fully in speech: hot path)
            idle_root = np.array([position[0], self.idle.base_root[1], position[2]])  # idle in place
            rotations, root = self.crossfade.mix(t, self.idle.rotations(t), idle_root, rotations, position)
        if self.seed_fade is not None and self.seed_fade.weight(t) < SPEECH:
            return self._from_seed(t, rotations, root)
        return rotations, root

    def _from_seed(self, t: float, rotations: np.ndarray, root: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The stream's (J, 4), (3,) pose cross-faded from the seed motion's last pose (weight 0 at t = 0)."""
        seed = self.config.seed_motion
        seed_root = np.array([root[0], seed.height, root[2]])  # the seed's pose where the avatar stands
        return self.seed_fade.mix(t, seed.rotations, seed_root, rotations, root)

    def _held_pose(self, frame: int, t: float) -> tuple[np.ndarray, np.ndarray]:
        """The last good pose in place of a non-finite one (the idle pose before any)."""
        self.nonfinite_poses += 1
        if self.nonfinite_poses == 1:
            logger.warning("pose %d came out NaN or infinite; holding the last good pose instead "
                           "(counted as nonfinite_poses; later ones are not logged)", frame)
        if self._last_good is None:
            return self.idle.rotations(t), self.idle.base_root.copy()
        return self._last_good

    def _capture_time(self, frame: int) -> float:
        """Capture time of the first audio sample of ``frame``, from the newest chunk's timestamp.

        A microphone's chunk times are estimates that jitter (PortAudio's ADC times through PulseAudio
        moved by tens of ms); a frame is never given a time before the previous frame's, so presentation
        times stay in order for the scheduler."""
        start, time = self._anchor
        estimate = time + (int(frame_boundary(frame, self.sample_rate, self.fps)) - start) / self.sample_rate
        self._last_capture = max(estimate, self._last_capture)
        return self._last_capture
