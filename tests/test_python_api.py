"""The library: ``gesturecast.generate``, ``Motion``, ``Stream``, ``Settings``, ``Outputs`` (docs/python-api.md).

Parity is exact: the library, the command line and the streaming path run one session, so the same audio,
settings and seed give the same bits whichever door they come through and however the audio is cut.
"""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import soundfile

import gesturecast
from gesturecast.bridges.control import message_controls
from gesturecast.controls import ControlError
from gesturecast.errors import UserError
from gesturecast.models.audio.dsp import frames_complete
from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio
from gesturecast.models.motion.bvh import read_bvh
from gesturecast.models.motion.motion import MOTION_FPS

SECONDS = 4


@pytest.fixture(scope="module")
def speech() -> np.ndarray:
    """(n,) float32: 4 s of the bundled sample at 16 kHz."""
    return load_audio(PACKAGED_SAMPLE)[: SECONDS * SAMPLE_RATE]


@pytest.fixture(scope="module")
def speech_file(tmp_path_factory, speech) -> Path:
    path = tmp_path_factory.mktemp("api") / "talk.wav"
    soundfile.write(path, speech, SAMPLE_RATE, subtype="FLOAT")
    return path


@pytest.fixture(scope="module")
def motion(speech_file) -> gesturecast.Motion:
    return gesturecast.generate(speech_file, style="happy")


def test_generate_gives_a_motion_of_the_canonical_skeleton(motion):
    frames = SECONDS * 30
    assert motion.rotations.shape == (frames, len(motion.bone_names), 4)
    assert motion.root_positions.shape == (frames, 3)
    assert motion.bone_names[:2] == ("Hips", "Spine") and motion.fps == 30.0
    assert motion.visemes.shape == (frames, 5) and motion.viseme_names == ("A", "I", "U", "E", "O")
    assert np.allclose(np.linalg.norm(motion.rotations, axis=-1), 1.0, atol=1e-5)
    assert motion.speaking.any() and all(frame.style == "happy" for frame in motion.frames)


def test_an_array_gives_the_same_bits_as_its_file(motion, speech):
    from_array = gesturecast.generate(speech, SAMPLE_RATE, style="happy")
    assert np.array_equal(from_array.rotations, motion.rotations)
    assert np.array_equal(from_array.root_positions, motion.root_positions)


def test_stereo_int16_at_48k_is_converted(speech):
    import soxr

    stereo = np.stack([speech, speech], axis=1)  # (n, 2)
    at_48k = (soxr.resample(stereo, SAMPLE_RATE, 48000) * 32767).astype(np.int16)  # (3n, 2)
    motion = gesturecast.generate(at_48k, 48000, lipsync="off")
    assert motion.num_frames == SECONDS * 30 and motion.visemes is None


def test_the_library_writes_what_the_command_line_writes(motion, speech_file, tmp_path, cli_here):
    motion.save(tmp_path / "api.bvh")
    assert cli_here("generate", str(speech_file), "--style", "happy", "-o", str(tmp_path / "cli.bvh")).returncode == 0
    assert (tmp_path / "api.bvh").read_bytes() == (tmp_path / "cli.bvh").read_bytes()


def test_save_writes_bvh_vrma_and_json_and_refuses_other_suffixes(motion, tmp_path):
    bvh = read_bvh(motion.save(tmp_path / "m.bvh"))
    assert bvh.num_frames == motion.num_frames
    assert (tmp_path / "m.vrma").exists() is False and motion.save(tmp_path / "m.vrma").read_bytes()[:4] == b"glTF"
    document = json.loads(motion.save(tmp_path / "m.json").read_text())
    assert len(document["frames"]) == motion.num_frames and document["visemes"] == list(motion.viseme_names)
    with pytest.raises(UserError, match=r"\.glb"):
        motion.save(tmp_path / "m.glb")
    assert not (tmp_path / "m.glb").exists()


@pytest.mark.parametrize("block", [160, 512, 4801])
def test_a_stream_gives_the_bits_of_generate_whatever_the_block_size(motion, speech, block):
    received = []
    with gesturecast.Stream(style="happy", paced=False, warm=False, on_frame=received.append) as stream:
        pushed = [frame for start in range(0, speech.shape[0], block)
                  for frame in stream.push(speech[start : start + block], SAMPLE_RATE)]
    pushed += stream.close()  # the with block closed it: nothing more
    assert len(pushed) < motion.num_frames  # the look-ahead's last frames come from the close
    assert [frame.seq for frame in received] == list(range(motion.num_frames))
    assert np.array_equal(np.stack([frame.rotations for frame in received]), motion.rotations)


def test_flush_hands_over_the_frames_owed_and_the_stream_goes_on(motion, speech):
    """push() gives frames as they become ready; flush() the rest of the audio pushed so far, and the next block
    follows the silence it added; close() the last ones."""
    half = speech.shape[0] // 2
    owed = frames_complete(half, SAMPLE_RATE, int(MOTION_FPS))
    with gesturecast.Stream(style="happy", paced=False, warm=False) as stream:
        pushed = stream.push(speech[:half], SAMPLE_RATE)
        flushed = stream.flush()
        assert stream.flush() == []  # nothing more is owed
        later = stream.push(speech[half:], SAMPLE_RATE)
        closing = stream.close()
    assert len(pushed) < owed <= len(pushed) + len(flushed)
    assert np.array_equal(np.stack([f.rotations for f in pushed]), motion.rotations[: len(pushed)])
    frames = pushed + flushed + later + closing
    assert [frame.seq for frame in frames] == list(range(len(frames)))
    assert len(frames) > motion.num_frames  # the flush's silence is part of the stream


def test_a_stream_sizes_and_pauses_its_gestures_live(speech):
    with gesturecast.Stream(paced=False, warm=False, intensity=0.5) as stream:
        stream.push(speech[:SAMPLE_RATE], SAMPLE_RATE)
        stream.control(intensity=1.5, pause=True)
        stream.push(speech[SAMPLE_RATE:], SAMPLE_RATE)
        controls = stream.session.controls
        assert (controls.intensity, controls.paused, controls.gesture_size) == (1.5, True, 0.0)
        with pytest.raises(UserError, match=r"intensity must be within \[0, 2\]"):
            stream.control(intensity=3)


def test_a_stream_takes_controls_and_refuses_what_the_model_lacks(speech):
    with gesturecast.Stream(paced=False, warm=False) as stream:
        stream.push(speech[: SAMPLE_RATE], SAMPLE_RATE)
        stream.control(style="old")
        frames = stream.push(speech[SAMPLE_RATE:], SAMPLE_RATE)
        with pytest.raises(UserError, match="hapy"):
            stream.control(style="hapy")
    assert frames[-1].style == "old"
    with pytest.raises(UserError, match="closed"):
        stream.push(speech, SAMPLE_RATE)


BAD_CONTROLS = [{"gamma": 50}, {"guidance": float("nan")}, {"audio_guidance": float("inf")}, {"guidance": 1e6},
                {"gamma": 1e30}, {"guidance": "x"}, {"root": "flying"}, {"gesture": None}, {"volume": 3}]


def test_a_stream_refuses_a_bad_control_at_the_call_in_the_websockets_words(speech):
    """Every refused field fails at ``control()`` itself, with the reason a WebSocket client is sent, and the stream
    goes on with finite poses (nan guidance used to freeze the avatar; a bad root used to fail a later push)."""
    with gesturecast.Stream(paced=False, warm=False) as stream:
        for fields in BAD_CONTROLS:
            with pytest.raises(ControlError) as wire_error:
                message_controls({"type": "control", **fields})
            with pytest.raises(UserError) as call_error:
                stream.control(**fields)
            assert str(call_error.value) == str(wire_error.value), fields
        frames = stream.push(speech, SAMPLE_RATE)
    assert frames and all(np.isfinite(frame.rotations).all() for frame in frames)
    with gesturecast.Stream(paced=False, warm=False) as stream, pytest.raises(
            UserError, match=r"^gamma must be within \[-2, 3\], got 50$"):
        stream.control(gamma=50)


def test_a_closed_stream_refuses_controls_gestures_and_words(speech):
    stream = gesturecast.Stream(paced=False, warm=False)
    stream.close()
    for call in (lambda: stream.control(style="old"), lambda: stream.gesture("wave"),
                 lambda: stream.spoken("hello"), lambda: stream.words([{"word": "hello", "start": 1.0}])):
        with pytest.raises(UserError, match="this stream is closed"):
            call()


@pytest.mark.parametrize("start", [float("nan"), float("inf"), -1.0, "soon"])
def test_spoken_words_need_a_finite_stream_time(start):
    with gesturecast.Stream(paced=False, warm=False) as stream, pytest.raises(
            UserError, match="^start must be"):
        stream.spoken("hello", start)


def test_a_stream_records_bvh_through_its_outputs(speech, tmp_path):
    outputs = gesturecast.Outputs(bvh=tmp_path / "take.bvh")
    with gesturecast.Stream(gesturecast.Settings(seed=3), outputs, paced=False, warm=False) as stream:
        stream.push(speech, SAMPLE_RATE)
    assert read_bvh(tmp_path / "take.bvh").num_frames == SECONDS * 30
    assert stream.report().audio_seconds == pytest.approx(SECONDS)


def test_settings_are_frozen_and_checked_once_with_the_flags_words():
    settings = gesturecast.Settings(style="old", latency="low", part_styles={"arms": "happy"})
    with pytest.raises(dataclasses.FrozenInstanceError):
        settings.steps = 9
    assert settings.part_styles == gesturecast.Settings(part_styles=["arms=happy"]).part_styles
    assert settings.replace(seed=4).seed == 4 and settings.seed == 0
    for bad, words in [({"steps": 0}, "steps must be an integer from 1 to 1000, got 0"),
                       ({"guidance": float("nan")}, "guidance must be a finite number"),
                       ({"smoothing": 1000}, "smoothing must be an integer from 0 to 15"),
                       ({"latency": "fast"}, "latency must be one of low, balanced, quality"),
                       ({"stpes": 3}, "unknown setting(s) stpes"),
                       ({"part_styles": "arms=happy"}, "part_styles wants PART=STYLE items")]:
        with pytest.raises(UserError, match=words.replace("(", r"\(").replace(")", r"\)")):
            gesturecast.Settings().replace(**bad)


def test_a_flag_and_its_setting_refuse_a_value_in_the_same_words(speech_file, tmp_path, cli_here):
    result = cli_here("generate", str(speech_file), "--steps", "0", "-o", str(tmp_path / "x.bvh"))
    assert result.returncode == 2
    assert "--steps: must be an integer from 1 to 1000, got '0'" in result.stderr


def test_outputs_are_checked_when_made():
    assert gesturecast.Outputs(vmc="10.0.0.2", vmc_role="assistant").vmc_address() == ("10.0.0.2", 39540)
    with pytest.raises(UserError, match="vmc wants HOST:PORT"):
        gesturecast.Outputs(vmc="host:99999")
    with pytest.raises(UserError, match="goes with a WebSocket port"):
        gesturecast.Outputs(avatar=Path("a.vrm"))


def test_import_gesturecast_loads_no_model_runtime():
    code = "import sys, gesturecast; print('onnxruntime' in sys.modules, 'gesturecast.realtime' in sys.modules)"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.split() == ["False", "False"]


def test_a_stream_waves_at_hello_given_as_words_or_as_a_words_control(speech):
    for send in ("words", "control"):
        with gesturecast.Stream(paced=False, warm=False) as stream:
            frames = stream.push(speech[:SAMPLE_RATE], SAMPLE_RATE)
            words = [{"word": "Hello", "start": 2.5, "end": 2.8}]
            stream.words(words) if send == "words" else stream.control(words=words)
            frames += stream.push(speech[SAMPLE_RATE:], SAMPLE_RATE)
        frames += stream.close()
        waving = [frame.seq / 30 for frame in frames if frame.gesture == "wave"]
        assert waving and waving[0] < 2.5 < waving[-1], send


def test_a_gesture_by_its_old_name_plays_the_gesture_it_is_called_now(speech):
    with gesturecast.Stream(paced=False, warm=False) as stream:
        stream.gesture("bye")  # the shipped lexicon calls it hand-up now: what a person sees
        frames = stream.push(speech, SAMPLE_RATE)
    assert any(frame.gesture == "hand-up" for frame in frames)


def test_a_gesture_needs_a_lexicon(speech):
    with gesturecast.Stream(paced=False, warm=False, gestures=None) as stream, pytest.raises(
            UserError, match="no gesture lexicon"):
        stream.gesture("wave")


def test_a_stream_left_open_at_exit_finishes_its_recording_and_says_so(tmp_path):
    """Without ``with`` or close(), the BVH was lost (a hidden temporary left behind, no warning)."""
    take = tmp_path / "noclose.bvh"
    code = ("import numpy, gesturecast; "
            f"stream = gesturecast.Stream(outputs=gesturecast.Outputs(bvh={str(take)!r}), paced=False, warm=False); "
            "stream.push(numpy.zeros(16000, numpy.float32), 16000)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert read_bvh(take).num_frames == 30
    assert [path.name for path in tmp_path.iterdir()] == [take.name]  # no temporary left
    assert f"still open at exit: closing it and finishing its recording {take}" in result.stderr


def test_floats_at_int16_scale_and_bytes_are_refused_alike_at_every_door(speech, tmp_path):
    loud = speech * 32767  # float32 at int16 scale: other motion than ``speech``, taken silently before
    soundfile.write(tmp_path / "loud.wav", loud, SAMPLE_RATE, subtype="FLOAT")
    with gesturecast.Stream(paced=False, warm=False) as stream:
        for call in (lambda: stream.push(loud, SAMPLE_RATE), lambda: gesturecast.generate(loud, SAMPLE_RATE),
                     lambda: gesturecast.generate(tmp_path / "loud.wav")):
            with pytest.raises(UserError, match="far beyond full scale: float audio is in"):
                call()
        with pytest.raises(UserError, match="not bytes; 16-bit PCM bytes go to Stream.push_pcm16"):
            stream.push(speech.tobytes(), SAMPLE_RATE)


def test_push_pcm16_takes_mono_bytes_without_a_channel_count(speech):
    pcm = np.round(speech * 32767).astype("<i2")  # (n,)
    with gesturecast.Stream(paced=False, warm=False) as by_bytes, \
            gesturecast.Stream(paced=False, warm=False) as by_array:
        from_bytes, from_array = by_bytes.push_pcm16(pcm.tobytes(), SAMPLE_RATE), by_array.push(pcm, SAMPLE_RATE)
    assert from_bytes and len(from_bytes) == len(from_array)
    np.testing.assert_array_equal(np.stack([f.rotations for f in from_bytes]),
                                  np.stack([f.rotations for f in from_array]))


STOPPED_CLOCK = """
import threading
class StoppedClock:  # a test's clock that only a test moves: waiting on it waits for ever
    def now(self): return 0.0
    def sleep_until(self, t): threading.Event().wait() if t > 0 else None
    def wait_until(self, t, event): return event.wait() if t > 0 else event.is_set()
"""


def test_a_stream_on_a_stopped_clock_left_open_at_exit_does_not_hang_the_exit(tmp_path):
    """Closing at exit waits for the last frames' times; on a clock that no longer moves it stops instead."""
    take = tmp_path / "stopped.bvh"
    code = (STOPPED_CLOCK + "import numpy, gesturecast\n"
            f"stream = gesturecast.Stream(outputs=gesturecast.Outputs(bvh={str(take)!r}), clock=StoppedClock(), "
            "warm=False)\nstream.push(numpy.zeros(16000, numpy.float32), 16000)\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and "still open at exit" in result.stderr
    assert [path.name for path in tmp_path.iterdir()] in ([], [take.name])  # no temporary left
