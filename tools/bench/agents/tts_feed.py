"""A TTS service as a voice agent's pipeline sees it, for ``gesturecast bench pipecat``: each reply of
:mod:`gesturecast.tools.bench.gesture_set.texts_agent` spoken by espeak-ng (exact word times), its sentences
synthesised one after another faster than real time and pushed as 20 ms audio frames, with the text reported the way
the chosen service reports it (:data:`ORDERS`).

Stream time counts the audio pushed to the stream; the replies follow one another with no audio between them, so a
word's stream time is where its sample falls in the concatenated replies.
"""

from __future__ import annotations

import asyncio
from dataclasses import dataclass

import numpy as np
from pipecat.frames.frames import Frame, OutputAudioRawFrame, TTSStartedFrame, TTSStoppedFrame, TTSTextFrame

from gesturecast.models.audio.files import SAMPLE_RATE
from gesturecast.realtime.gestures.speech_acts import MARKS
from gesturecast.tools.bench.speech.espeak_words import spoken
from gesturecast.tools.gestures.speech_act_training import parse_marked

# how the service reports its text: a sentence's text after its audio (Pipecat 1.14's TTS services without word
# timestamps), before it, or each word's text with its first audio frame
ORDERS = ("after", "before", "words")
FRAME_S = 0.02
TTS_SPEED = 4.0  # seconds of audio a service synthesises per second
TURN_GAP_S = 1.0  # wall seconds between the end of a reply's audio and the next reply (the user speaks)


@dataclass(frozen=True)
class IntendedCue:
    reply: str
    intent: str
    word: str
    time: float  # the marked word's start (stream s)


@dataclass(frozen=True)
class Sentence:
    text: str
    audio: np.ndarray  # (n,) 16 kHz float32
    word_starts: tuple[float, ...]  # each token's start (s from the sentence's start)


@dataclass(frozen=True)
class Reply:
    name: str
    sentences: tuple[Sentence, ...]

    @property
    def seconds(self) -> float:
        return sum(len(s.audio) for s in self.sentences) / SAMPLE_RATE


def speak_replies(replies: dict[str, tuple[str, ...]], cache, voice: str | None = None
                  ) -> tuple[list[Reply], list[IntendedCue]]:
    """The replies spoken (sentence by sentence, in the espeak-ng ``voice``; None: its default) and their intended
    cues at stream times."""
    spoken_replies, intended, start = [], [], 0.0
    for name, marked_sentences in replies.items():
        sentences = []
        for marked in marked_sentences:
            tokens, marks = parse_marked(marked)
            audio, timed = spoken(" ".join(tokens), cache, voice)
            intended += [IntendedCue(name, MARKS[mark], timed[i].text, start + timed[i].start)
                         for i, mark in sorted(marks.items())]
            sentences.append(Sentence(" ".join(tokens), audio, tuple(w.start for w in timed)))
            start += len(audio) / SAMPLE_RATE
        spoken_replies.append(Reply(name, tuple(sentences)))
    return spoken_replies, intended


def audio_frames(audio: np.ndarray) -> list[OutputAudioRawFrame]:
    """(n,) float audio → 20 ms 16-bit mono frames at 16 kHz."""
    pcm = np.round(np.clip(audio, -1, 1) * 32767).astype("<i2")
    step = round(FRAME_S * SAMPLE_RATE)
    return [OutputAudioRawFrame(audio=pcm[s : s + step].tobytes(), sample_rate=SAMPLE_RATE, num_channels=1)
            for s in range(0, len(pcm), step)]


def sentence_frames(sentence: Sentence, order: str) -> list[Frame]:
    """One sentence's frames as a service of ``order`` pushes them."""
    audio = audio_frames(sentence.audio)
    if order == "after":
        return [*audio, TTSTextFrame(sentence.text, text_type="sentence")]
    if order == "before":
        return [TTSTextFrame(sentence.text, text_type="sentence"), *audio]
    firsts = {min(round(t / FRAME_S), len(audio) - 1): token
              for t, token in zip(sentence.word_starts, sentence.text.split(), strict=True)}
    return [f for k, frame in enumerate(audio)
            for f in ([TTSTextFrame(firsts[k], text_type="word")] if k in firsts else []) + [frame]]


async def feed_replies(queue, replies: list[Reply], order: str, queued_at: dict[int, float]) -> None:
    """Queue the replies' frames (``queue``: an async callable taking a list of frames) at a service's pace; the
    loop time each audio frame was queued goes to ``queued_at`` by the frame's id (Pipecat numbers every frame)."""
    loop = asyncio.get_running_loop()
    for reply in replies:
        await queue([TTSStartedFrame()])
        for sentence in reply.sentences:
            await asyncio.sleep(len(sentence.audio) / SAMPLE_RATE / TTS_SPEED)  # synthesis
            frames = sentence_frames(sentence, order)
            queued_at.update({f.id: loop.time() for f in frames if isinstance(f, OutputAudioRawFrame)})
            await queue(frames)
        await queue([TTSStoppedFrame()])
        await asyncio.sleep(reply.seconds * (1 - 1 / TTS_SPEED) + TURN_GAP_S)  # the reply plays out, the user speaks
