"""Every word reaches the cue plan through the same two functions, whichever door it enters by: it is checked by
:func:`gesturecast.controls.parse_words` and the cues it decides are placed by
:meth:`GestureDirector.place_word_cues`. Followed here from ``generate --transcript``, from a WebSocket ``words``
message and from ``Stream.spoken``."""

import json
import sys
from unittest import mock

import numpy as np
import pytest
import soundfile
from websockets.sync.client import connect

import gesturecast
from gesturecast import cli, controls
from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.realtime.gestures.director import GestureDirector

TIMEOUT_S = 10.0
WORDS = [{"word": "Hello", "start": 0.5, "end": 0.8}, {"word": "everyone.", "start": 0.8, "end": 1.2}]


def spy_everywhere(monkeypatch, function) -> mock.MagicMock:
    """A spy that wraps ``function`` in every loaded module that holds it by name (``from … import`` copies)."""
    spy = mock.MagicMock(wraps=function)
    for module in list(sys.modules.values()):
        for name, value in list(vars(module).items()) if module is not None else ():
            if value is function:
                monkeypatch.setattr(module, name, spy)
    return spy


@pytest.fixture
def route(monkeypatch) -> tuple[mock.MagicMock, mock.MagicMock]:
    """(parse_words spy, place_word_cues spy), installed for the test."""
    import gesturecast.realtime.gestures.transcripts  # noqa: F401 (loaded, so its copy of parse_words is spied on)
    import gesturecast.realtime.run.stream  # noqa: F401

    parsed = spy_everywhere(monkeypatch, controls.parse_words)
    placed = mock.MagicMock(wraps=GestureDirector.place_word_cues)
    monkeypatch.setattr(GestureDirector, "place_word_cues", lambda self, *args: placed(self, *args))
    return parsed, placed


def parsed_texts(parsed: mock.MagicMock) -> list[str]:
    return [item["word"] for call in parsed.call_args_list for item in call.args[0]]


def placed_phrases(placed: mock.MagicMock) -> list[str]:
    """The sources (phrases as spoken) of the cues each call placed."""
    return [cue.source for call in placed.call_args_list for cue in (*call.args[1], *call.args[2])]


def test_a_transcripts_words_pass_the_two_functions(route, tmp_path, speech_16k):
    parsed, placed = route
    (tmp_path / "words.json").write_text(json.dumps(WORDS))
    soundfile.write(tmp_path / "talk.wav", speech_16k[: 2 * SAMPLE_RATE], SAMPLE_RATE)
    assert cli.main(["generate", str(tmp_path / "talk.wav"), "--transcript", str(tmp_path / "words.json"),
                     "-o", str(tmp_path / "talk.bvh")]) == 0
    assert parsed_texts(parsed) == ["Hello", "everyone."]
    assert placed_phrases(placed) == ["Hello"]


def test_a_words_messages_words_pass_the_two_functions(route, speech_16k):
    parsed, placed = route
    with gesturecast.Stream(outputs=gesturecast.Outputs(ws=0), paced=False, warm=False) as stream:
        port = stream.bridges.bridges[0].port
        with connect(f"ws://127.0.0.1:{port}/", open_timeout=TIMEOUT_S) as client:
            client.recv(TIMEOUT_S)  # the hello
            client.send(json.dumps({"type": "words", "words": WORDS}))
            assert json.loads(client.recv(TIMEOUT_S))["type"] == "ack"
        stream.push(speech_16k[: 2 * SAMPLE_RATE], SAMPLE_RATE)  # the controls are applied at the next latent
    assert parsed_texts(parsed) == ["Hello", "everyone."]
    assert placed_phrases(placed) == ["Hello"]


def test_spoken_words_pass_the_two_functions(route):
    parsed, placed = route
    with gesturecast.Stream(paced=False, warm=False) as stream:
        stream.push(np.zeros(SAMPLE_RATE // 2, np.float32), SAMPLE_RATE)
        stream.spoken("Hello everyone.", 0.5)
    assert parsed_texts(parsed) == ["Hello", "everyone."]
    assert placed_phrases(placed) == ["Hello"]


SCRIPT = "Hello everyone. Thank you so much for coming."


def test_a_plain_text_scripts_words_pass_the_two_functions(route, tmp_path):
    from gesturecast.tools.bench.speech.espeak_words import spoken

    parsed, placed = route
    audio, _ = spoken(SCRIPT, tmp_path)
    soundfile.write(tmp_path / "talk.wav", audio, SAMPLE_RATE)
    (tmp_path / "talk.txt").write_text(SCRIPT + "\n")  # beside the audio: read without --transcript
    assert cli.main(["generate", str(tmp_path / "talk.wav"), "-o", str(tmp_path / "talk.bvh")]) == 0
    assert parsed_texts(parsed) == SCRIPT.split() * 2  # the script when read, then its cueing sentences aligned
    assert placed_phrases(placed) == ["Hello", "Thank you so much"]


def test_a_text_messages_words_pass_the_two_functions(route, tmp_path):
    from gesturecast.tools.bench.speech.espeak_words import spoken

    parsed, placed = route
    audio, _ = spoken("Hello everyone.", tmp_path)
    with gesturecast.Stream(outputs=gesturecast.Outputs(ws=0), paced=False, warm=False) as stream:
        port = stream.bridges.bridges[0].port
        with connect(f"ws://127.0.0.1:{port}/", open_timeout=TIMEOUT_S) as client:
            client.recv(TIMEOUT_S)  # the hello
            client.send(json.dumps({"type": "words", "text": "Hello everyone."}))  # before its audio, no times
            assert json.loads(client.recv(TIMEOUT_S))["type"] == "ack"
        stream.push(np.zeros(SAMPLE_RATE // 4, np.float32), SAMPLE_RATE)  # the controls are applied at the next latent
        stream.push(audio, SAMPLE_RATE)
        stream.push(np.zeros(SAMPLE_RATE, np.float32), SAMPLE_RATE)
        assert stream.session.gestures.alignments.to_dict()["onset"] == 1  # "Hello" opens it: its voiced onset
    assert parsed_texts(parsed) == ["Hello", "everyone."]
    assert placed_phrases(placed) == ["Hello"]


def test_a_sentence_spoken_without_a_start_is_placed_on_its_audio(route, tmp_path):
    from gesturecast.tools.bench.speech.espeak_words import spoken

    parsed, placed = route
    audio, timed = spoken("Hello everyone.", tmp_path)
    with gesturecast.Stream(paced=False, warm=False) as stream:
        stream.push(np.zeros(SAMPLE_RATE // 2, np.float32), SAMPLE_RATE)
        stream.push(np.concatenate([audio, np.zeros(SAMPLE_RATE // 2, np.float32)]), SAMPLE_RATE)
        stream.spoken("Hello everyone.")  # a recogniser's transcript, after its audio and the pause after it
        assert stream.session.gestures.alignments.to_dict()["onset"] == 1  # "Hello" opens it: its voiced onset
    assert parsed_texts(parsed) == ["Hello", "everyone."]
    [call] = parsed.call_args_list
    assert abs(call.args[0][0]["start"] - (0.5 + timed[0].start)) < 0.05  # the cued word, where its speech starts
    assert placed_phrases(placed) == ["Hello"]


def test_a_sentence_said_with_its_audio_is_cued_before_its_audio_is_generated(route, tmp_path):
    from gesturecast.tools.bench.speech.espeak_words import spoken

    parsed, placed = route
    audio, timed = spoken("Hello everyone.", tmp_path)
    with gesturecast.Stream(paced=False, warm=False) as stream:
        said = np.concatenate([np.zeros(SAMPLE_RATE // 2, np.float32), audio])  # the speech a TTS service made
        stream.say("Hello everyone.", said, SAMPLE_RATE)
        [outcome] = stream.session.gestures.cues.outcomes
        assert stream.audio_seconds == pytest.approx(0.5 + len(audio) / SAMPLE_RATE)
    assert outcome.status == "on time" and abs(outcome.stroke_time - (0.5 + timed[0].start)) < 0.2
    assert parsed_texts(parsed) == ["Hello", "everyone."]
    assert placed_phrases(placed) == ["Hello"]


def test_the_library_places_a_plain_text_script_on_an_array_of_samples(route, tmp_path):
    from gesturecast.tools.bench.speech.espeak_words import spoken

    parsed, placed = route
    audio, _ = spoken(SCRIPT, tmp_path)
    (tmp_path / "script.txt").write_text(SCRIPT)
    gesturecast.generate(audio, SAMPLE_RATE, transcript=tmp_path / "script.txt")
    assert parsed_texts(parsed) == SCRIPT.split() * 2  # the script when read, then its cueing sentences aligned
    assert placed_phrases(placed) == ["Hello", "Thank you so much"]
