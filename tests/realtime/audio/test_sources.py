"""File sources (fast and paced on a FakeClock) and the microphone's error paths on this machine."""

import numpy as np
import pytest
import soundfile

from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.realtime.audio.portaudio import (
    InputDevice,
    resolve_input_device,
    translate_import_error,
    translate_stream_error,
)
from gesturecast.realtime.audio.sources import FastFileSource, MicSource, PacedFileSource
from gesturecast.realtime.timing.clock import FakeClock

CHUNK = 512


@pytest.fixture(scope="module")
def speech_file(shared_data, tmp_path_factory):
    path = tmp_path_factory.mktemp("audio") / "speech_22k.wav"
    audio = load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")[: 2 * SAMPLE_RATE]
    import soxr

    soundfile.write(path, soxr.resample(audio, SAMPLE_RATE, 22050), 22050, subtype="PCM_16")
    return path


def test_fast_source_yields_the_whole_file_in_fixed_chunks(speech_file):
    source = FastFileSource(speech_file, chunk_samples=CHUNK)
    chunks = list(source)
    assert all(c.samples.shape[0] == CHUNK for c in chunks[:-1])
    assert [c.start_sample for c in chunks] == list(range(0, CHUNK * len(chunks), CHUNK))
    np.testing.assert_array_equal(np.concatenate([c.samples for c in chunks]), load_audio(speech_file))
    assert source.stats().samples == load_audio(speech_file).shape[0]
    assert chunks[3].capture_time == pytest.approx(3 * CHUNK / SAMPLE_RATE)


def test_paced_source_releases_chunks_at_real_time_on_the_clock(speech_file):
    clock = FakeClock(100.0)
    source = PacedFileSource(speech_file, chunk_samples=CHUNK, clock=clock)
    for chunk in source:
        end = chunk.start_sample + chunk.samples.shape[0]
        assert clock.now() == pytest.approx(100.0 + end / SAMPLE_RATE)
        assert chunk.capture_time == pytest.approx(100.0 + chunk.start_sample / SAMPLE_RATE)
    assert clock.now() == pytest.approx(100.0 + load_audio(speech_file).shape[0] / SAMPLE_RATE)


def test_close_stops_iteration(speech_file):
    source = FastFileSource(speech_file, chunk_samples=CHUNK)
    received = 0
    for _ in source:
        received += 1
        source.close()
    assert received == 1


def test_microphone_error_is_one_clear_line():
    """CI machines have PortAudio but no input device; without PortAudio the hint names the package."""
    with pytest.raises(UserError) as error:
        MicSource()
    assert "--input FILE" in str(error.value) and "\n" not in str(error.value)


def test_missing_portaudio_message_names_the_package():
    message = str(translate_import_error(OSError("PortAudio library not found")))
    assert "libportaudio2" in message and "--input FILE" in message


DEVICES = [InputDevice(0, "HDA Intel PCH: ALC257 Analog", 2, 44100.0, "ALSA"),
           InputDevice(3, "USB Audio Device: Mic", 1, 48000.0, "ALSA")]


@pytest.mark.parametrize(("spec", "index"), [(None, 0), ("3", 3), ("usb", 3), ("ALC257", 0)])
def test_device_selection_by_index_or_name(spec, index):
    assert resolve_input_device(spec, DEVICES).index == index


@pytest.mark.parametrize("spec", ["7", "ALSA", "webcam"])
def test_device_selection_errors(spec):
    with pytest.raises(UserError, match="device"):
        resolve_input_device(spec, DEVICES)


def test_refused_sample_rate_suggests_the_device_rate():
    sounddevice = pytest.importorskip("sounddevice", exc_type=OSError)  # needs the PortAudio library
    error = sounddevice.PortAudioError("Invalid sample rate", -9997)
    message = str(translate_stream_error(error, DEVICES[1], 22050))
    assert "refuses 22050 Hz" in message and "--sample-rate 48000" in message
