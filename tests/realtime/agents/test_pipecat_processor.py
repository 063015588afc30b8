"""GesturecastProcessor in real Pipecat pipelines: audio frames in (any rate / channels), poses out through a
real VMC bridge to a loopback UDP socket and a BVH, every frame passed on unchanged, style changes from a
style frame and from spoken text, and the offline example as a subprocess. Bounded in time."""

from __future__ import annotations

import asyncio
import os
import socket
import subprocess
import sys
import threading

import numpy as np
import pytest
import soundfile

pytest.importorskip("pipecat", reason="Pipecat is not installed (pip install 'gesturecast[pipecat]')")

from pipecat.frames.frames import Frame, InputAudioRawFrame, OutputAudioRawFrame, TTSTextFrame  # noqa: E402
from pipecat.processors.frame_processor import FrameDirection, FrameProcessor  # noqa: E402
from pipecat_frames import EXAMPLE, Recorder, run_pipeline  # noqa: E402
from pythonosc.osc_bundle import OscBundle  # noqa: E402

from gesturecast.bridges.output_settings import Outputs  # noqa: E402
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio  # noqa: E402
from gesturecast.models.motion.bvh import read_bvh  # noqa: E402
from gesturecast.realtime.agents.pipecat_processor import (  # noqa: E402
    SUGGESTED_HOLD_S,
    GesturecastProcessor,
    GestureStyleFrame,
)
from gesturecast.realtime.run.stream import Stream  # noqa: E402
from gesturecast.settings import Settings  # noqa: E402

SPEECH_S = 2.0
PIPELINE_BOUND_S = 120.0  # model load + 2 s of audio released in real time, on shared cores
DATAGRAM_BYTES = 65536
BONE_ADDRESS = "/VMC/Ext/Bone/Pos"
FRAMES_PER_S = 30
FRAME_S = 0.02


class VmcReceiver:
    """A UDP socket on a free loopback port, parsing every VMC bundle it receives on a thread."""

    def __init__(self) -> None:
        self.socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.socket.bind(("127.0.0.1", 0))
        self.socket.settimeout(0.2)
        self.addresses: list[str] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._receive, daemon=True)
        self._thread.start()

    @property
    def target(self) -> str:
        return f"127.0.0.1:{self.socket.getsockname()[1]}"

    def _receive(self) -> None:
        while not self._stop.is_set():
            try:
                data = self.socket.recv(DATAGRAM_BYTES)
            except TimeoutError:
                continue
            self.addresses.extend(message.address for message in OscBundle(data))

    def close(self) -> None:
        self._stop.set()
        self._thread.join()
        self.socket.close()


@pytest.fixture
def vmc_receiver():
    receiver = VmcReceiver()
    yield receiver
    receiver.close()


@pytest.fixture(scope="module")
def speech(shared_data) -> np.ndarray:
    """(n,) float32: 2 s of synthetic speech at 16 kHz."""
    return load_audio(shared_data / "speech" / "tts_03_en-gb.wav")[: int(SPEECH_S * SAMPLE_RATE)]


def pcm_frames(audio: np.ndarray, rate: int, channels: int, frame_type: type) -> list[Frame]:
    """(n,) float audio at ``rate`` as 20 ms int16 frames with ``channels`` identical channels."""
    pcm = np.repeat(np.round(audio * 32767).astype("<i2")[:, None], channels, axis=1)  # (n, C)
    step = round(FRAME_S * rate)
    return [frame_type(audio=pcm[s : s + step].tobytes(), sample_rate=rate, num_channels=channels)
            for s in range(0, pcm.shape[0], step)]




def test_tts_audio_drives_vmc_and_bvh_and_a_style_frame_changes_the_style(tiny_model, speech, vmc_receiver,
                                                                          tmp_path):
    upsampled = np.interp(np.arange(int(SPEECH_S * 48000)) * SAMPLE_RATE / 48000, np.arange(speech.shape[0]), speech)
    frames = pcm_frames(upsampled, 48000, 2, OutputAudioRawFrame)  # as a TTS at 48 kHz stereo sends it
    half = len(frames) // 2
    style = GestureStyleFrame(control={"style": "old"})
    frames = [*frames[:half], style, *frames[half:]]
    processor = GesturecastProcessor(Settings(model=tiny_model[1], style="neutral"),
                                     Outputs(vmc=vmc_receiver.target, bvh=tmp_path / "take.bvh"))
    recorder = Recorder()
    asyncio.run(asyncio.wait_for(run_pipeline([processor, recorder], frames), PIPELINE_BOUND_S))

    passed = [f for f in recorder.frames if isinstance(f, (OutputAudioRawFrame, GestureStyleFrame))]
    assert [id(f) for f in passed] == [id(f) for f in frames]  # every frame on, unchanged, in order
    assert processor.session.controls.describe() == "old"
    assert processor.audio_seconds == pytest.approx(SPEECH_S, abs=1e-2)
    bvh_frames = read_bvh(tmp_path / "take.bvh").motion.shape[0]
    assert abs(bvh_frames - SPEECH_S * FRAMES_PER_S) <= 1
    bones = vmc_receiver.addresses.count(BONE_ADDRESS)
    assert bones > 0 and bones % bvh_frames == 0  # every pose reached the receiver with all its bones


def test_user_audio_and_a_style_per_spoken_sentence(tiny_model, speech, tmp_path):
    sentences = {"Grumpy now.": {"style": "old"}}
    frames = pcm_frames(speech, SAMPLE_RATE, 1, InputAudioRawFrame)
    frames.insert(len(frames) // 2, TTSTextFrame("Grumpy now.", text_type="sentence"))
    processor = GesturecastProcessor(Settings(model=tiny_model[1]), Outputs(bvh=tmp_path / "u.bvh"),
                                     audio="input", style_for_text=sentences.get)
    asyncio.run(asyncio.wait_for(run_pipeline([processor], frames), PIPELINE_BOUND_S))
    assert processor.session.controls.describe() == "old"
    assert abs(read_bvh(tmp_path / "u.bvh").motion.shape[0] - SPEECH_S * FRAMES_PER_S) <= 1


class WordTimedTTS(FrameProcessor):
    """A TTS service's word frames: each TTSTextFrame it passes gets a presentation time on the pipeline's clock,
    ``ahead_s[word]`` from now, as word-timestamp services stamp the words they are about to speak."""

    def __init__(self, ahead_s: dict[str, float]) -> None:
        super().__init__()
        self.ahead_s = ahead_s

    async def process_frame(self, frame: Frame, direction: FrameDirection) -> None:
        await super().process_frame(frame, direction)
        if isinstance(frame, TTSTextFrame):
            frame.pts = self.get_clock().get_time() + round(self.ahead_s[frame.text] * 1e9)
        await self.push_frame(frame, direction)


def test_words_the_tts_speaks_cue_their_gestures_at_their_presentation_time(speech):
    """Words stamped before their audio: "Thank" cues nothing, "you." cues the bow with its stroke on "Thank",
    "Hello!" waves at its time; the frames given to the stream's callback say which gesture plays, and when."""
    ahead_s = {"Thank": 2.0, "you.": 2.3, "Hello!": 5.5}
    words = [TTSTextFrame(word, text_type="word") for word in ahead_s]
    audio = pcm_frames(np.tile(speech, 4), SAMPLE_RATE, 1, OutputAudioRawFrame)  # 8 s
    released = []
    processor = GesturecastProcessor(stream=Stream(Settings(), on_frame=released.append, paced=False))
    asyncio.run(asyncio.wait_for(run_pipeline([WordTimedTTS(ahead_s), processor], [*words, *audio]),
                                 PIPELINE_BOUND_S))
    playing = {name: [f.seq / FRAMES_PER_S for f in released if f.gesture == name] for name in ("bow", "wave")}
    assert playing["bow"][0] < ahead_s["Thank"] < playing["bow"][-1] < ahead_s["Hello!"]
    assert playing["wave"][0] < ahead_s["Hello!"] < playing["wave"][-1]
    assert {f.gesture for f in released} == {"", "bow", "wave"}


def test_word_frames_that_come_with_their_audio_get_their_strokes_on_the_words_with_a_hold(speech):
    """A TTS that sends each word frame with its audio (no presentation time): without a hold the strokes come late;
    holding the audio by SUGGESTED_HOLD_S puts them on the words; every audio frame still goes on, in order."""
    audio = pcm_frames(np.tile(speech, 4), SAMPLE_RATE, 1, OutputAudioRawFrame)  # 8 s of 20 ms frames
    words = {100: "Hello,", 115: "it", 130: "is", 145: "me.",  # 2.0 s, 0.3 s apart
             250: "thank", 265: "you", 280: "so", 295: "much."}  # 5.0 s
    frames = [f for k, a in enumerate(audio) for f in ([TTSTextFrame(words[k], text_type="word")] if k in words
                                                        else []) + [a]]
    delays = {}
    for hold_s in (0.0, SUGGESTED_HOLD_S):
        processor = GesturecastProcessor(stream=Stream(Settings(), paced=False), hold_s=hold_s)
        recorder = Recorder()
        asyncio.run(asyncio.wait_for(run_pipeline([processor, recorder], frames), PIPELINE_BOUND_S))
        outcomes = list(processor.session.gestures.cues.outcomes)
        assert [o.cue.gesture for o in outcomes] == ["wave", "bow"]
        delays[hold_s] = [None if o.stroke_time is None else o.stroke_time - o.cue.time for o in outcomes]
        assert [id(f) for f in recorder.frames if isinstance(f, OutputAudioRawFrame)] == [id(f) for f in audio]
    assert delays[0.0][1] is None or delays[0.0][1] > 0.3  # "thanks" waits for its next words: late or dropped
    assert all(abs(d) <= 0.3 for d in delays[SUGGESTED_HOLD_S])


def test_the_offline_example_runs_a_pipeline_to_vmc_and_bvh(tiny_model, speech, vmc_receiver, tmp_path):
    wav = tmp_path / "speech.wav"
    soundfile.write(wav, speech, SAMPLE_RATE, subtype="PCM_16")
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    result = subprocess.run([sys.executable, str(EXAMPLE), str(wav), "--styles", "neutral,old", "--model",
                             str(tiny_model[1]), "--vmc", vmc_receiver.target, "--bvh", str(tmp_path / "ex.bvh")],
                            capture_output=True, text=True, timeout=PIPELINE_BOUND_S, env=env)
    assert result.returncode == 0, result.stderr[-3000:]
    assert "style at the end: old" in result.stderr
    assert read_bvh(tmp_path / "ex.bvh").motion.shape[0] > 0 and BONE_ADDRESS in vmc_receiver.addresses
