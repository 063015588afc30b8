"""The library's offline call: ``gesturecast.generate(audio) -> Motion`` (docs/python-api.md).

It runs the same session as ``gesturecast generate`` and ``live`` (the file or array fed as fast as possible,
:func:`gesturecast.realtime.run.engine.run_offline`), so a given audio, settings and seed give the same poses
through every door.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.frames import PoseFrame
from gesturecast.models.audio.files import load_audio
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS
from gesturecast.realtime.audio.sources import ArraySource, AudioSource, FastFileSource
from gesturecast.realtime.gestures.transcripts import (
    SCRIPT_SUFFIX,
    Transcript,
    read_transcript,
    script_transcript,
    words_from_list,
)
from gesturecast.realtime.run.engine import run_offline
from gesturecast.realtime.run.engine_setup import build_session
from gesturecast.realtime.run.offline_generate import frame_writer
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import Settings, with_overrides


@dataclass(frozen=True, eq=False)
class Motion:
    """Generated motion on the canonical skeleton (Unity HumanBodyBones names, 22 body joints then 15 finger
    joints per hand), internal frame: right-handed, Y-up, facing +Z, metres.

    rotations: (T, J, 4) local rotations, quaternions XYZW; identity = T-pose.
    root_positions: (T, 3) hips position.
    bone_names: the J joint names; fps: frames per second (30).
    visemes: (T, 5) mouth-shape weights in [0, 1] named by ``viseme_names``, or None with lip sync off.
    face: (T, 8) blink and emotion-preset weights in [0, 1] named by ``face_names``, or None with the face off.
    speaking: (T,) the voice-activity flag of each frame.
    frames: the pose frames themselves (times, style, flags), as a stream would deliver them.
    """

    rotations: np.ndarray
    root_positions: np.ndarray
    bone_names: tuple[str, ...]
    fps: float
    visemes: np.ndarray | None
    viseme_names: tuple[str, ...]
    speaking: np.ndarray
    frames: tuple[PoseFrame, ...] = field(repr=False)
    face: np.ndarray | None = None
    face_names: tuple[str, ...] = ()

    @classmethod
    def from_frames(cls, frames: list[PoseFrame], viseme_names: tuple[str, ...],
                    face_names: tuple[str, ...] = ()) -> Motion:
        lipsync = bool(frames) and frames[0].visemes is not None
        face = bool(frames) and frames[0].face is not None
        return cls(
            rotations=np.stack([frame.rotations for frame in frames]),  # (T, J, 4)
            root_positions=np.stack([frame.root_position for frame in frames]),  # (T, 3)
            bone_names=CANONICAL_WITH_HANDS.names,
            fps=MOTION_FPS,
            visemes=np.stack([frame.visemes for frame in frames]) if lipsync else None,  # (T, 5)
            viseme_names=viseme_names if lipsync else (),
            speaking=np.array([frame.speaking for frame in frames]),  # (T,)
            frames=tuple(frames),
            face=np.stack([frame.face for frame in frames]) if face else None,  # (T, 8)
            face_names=face_names if face else (),
        )

    def __repr__(self) -> str:
        return (f"Motion({self.num_frames} frames at {self.fps:g} fps = {self.duration:.2f} s, "
                f"{len(self.bone_names)} bones, visemes {'on' if self.visemes is not None else 'off'}, "
                f"face {'on' if self.face is not None else 'off'})")

    @property
    def num_frames(self) -> int:
        return self.rotations.shape[0]

    @property
    def duration(self) -> float:
        """Seconds."""
        return self.num_frames / self.fps

    def save(self, path: str | Path) -> Path:
        """Write ``.bvh`` (centimetres, any BVH tool), ``.vrma`` (VRM Animation) or ``.json`` (the pose stream);
        the file is replaced only once complete. Another suffix is a one-line error."""
        path = Path(path)
        with frame_writer(path, self.viseme_names, self.face_names) as writer:
            writer.write(list(self.frames))
            writer.save()
        return path


def generate(audio: str | Path | np.ndarray, sample_rate: int | None = None, settings: Settings | None = None, *,
             transcript: str | Path | list[dict] | None = None, **overrides) -> Motion:
    """Speech → motion, offline (as fast as the CPU allows): the poses ``gesturecast live`` would stream for the
    same audio, settings and seed.

    Args:
        audio: a file path (any format soundfile reads, any rate and channel count), or samples as an array,
            (n,) or (n, channels), float in [-1, 1] or int16, with ``sample_rate``.
        sample_rate: the rate of an array of samples (a file carries its own).
        settings: a :class:`Settings` (default ``Settings()``), by name: ``settings=Settings(style="old")``;
            ``overrides`` change single fields, e.g. ``generate("talk.wav", style="happy", seed=3)``.
        transcript: the audio's words, as a file (JSON word list, .srt, .vtt, or a plain-text script ``.txt``
            placed on the audio sentence by sentence) or a list of ``{"word", "start", "end"}`` (seconds): speech
            acts ("hello", "thank you") cue gestures of the lexicon with their stroke on the word.

    Returns:
        A :class:`Motion`: ``rotations`` (T, 52, 4) local XYZW quaternions on Unity HumanBodyBones names,
        ``root_positions`` (T, 3) metres, ``fps`` 30, mouth and face weights; ``motion.save("talk.bvh")`` writes
        it as ``.bvh``, ``.vrma`` or ``.json``.

    Raises:
        UserError: one line, for an unreadable file, a bad setting or a style the model does not know.

    Example::

        import gesturecast
        motion = gesturecast.generate("talk.wav", style="happy")
        print(motion)  # Motion(750 frames at 30 fps = 25.00 s, 52 bones, visemes on, face on)
        motion.save("talk.bvh")
    """
    settings = with_overrides(settings, overrides)
    source = _source(audio, sample_rate)
    session = build_session(settings, MonotonicClock())
    _transcript(transcript, audio, sample_rate).cue(session.gestures)
    frames, _ = run_offline(session, source)
    if not frames:
        raise UserError("the audio is shorter than one motion frame (1/30 s)")
    return Motion.from_frames(frames, settings.lipsync_names, settings.face_names)


def _transcript(transcript: str | Path | list[dict] | None, audio: str | Path | np.ndarray, sample_rate: int | None
                ) -> Transcript:
    """The transcript's words; a plain-text script (``.txt``) with the audio it is placed on."""
    if transcript is None:
        return Transcript()
    if isinstance(transcript, (str, Path)) and Path(transcript).suffix.lower() == SCRIPT_SUFFIX:
        samples = load_audio(audio) if isinstance(audio, (str, Path)) else ArraySource(audio, sample_rate).blocks[0]
        return script_transcript(Path(transcript), samples)
    if isinstance(transcript, (str, Path)):
        return Transcript(read_transcript(Path(transcript)))
    return Transcript(words_from_list(transcript, "transcript"))


def _source(audio: str | Path | np.ndarray, sample_rate: int | None) -> AudioSource:
    if isinstance(sample_rate, Settings):
        raise UserError("generate's second argument is the sample rate of an array; pass settings by name: "
                        "generate(audio, settings=Settings(...))")
    if isinstance(audio, (str, Path)):
        if sample_rate is not None:
            raise UserError("sample_rate goes with an array of samples; a file carries its own rate")
        return FastFileSource(audio)
    if sample_rate is None:
        raise UserError("an array of samples needs its sample_rate (e.g. generate(samples, 16000))")
    return ArraySource(audio, sample_rate)
