"""The unseen voices of ``gesturecast bench voices``, written down before any choice was made on them (2026-11-27).

Every voice belongs to a **group** (the kind of voice) and a **split**:

- ``held-out``: scored by the benchmark and never used to choose anything (a setting, a model, a candidate);
- ``dev``: voices of the same kinds that may be used to choose.

No bundled model was trained on any of these recordings (SHOW and the Flirty take are not in the default's
training data; docs/voices.md). Sources:

- **TTS** voices are made at run time, one sentence at a time from :data:`TEXTS`, joined with the pauses of
  :data:`PAUSES_S` — the turns a voice agent speaks. espeak-ng (formant and Klatt synthesis; its variants
  ``+f4``, ``+klatt3`` at several rates and pitches) and, in a group of their own added on 2026-11-27 before any
  model was scored on it, CMU Flite's built-in voices (``slt``, ``rms``, ``awb``: statistical parametric voices
  trained on recorded speakers; ``kal16``: diphone concatenation) — two engines unlike each other. Both must be
  on the PATH (the Makefile's SYSTEM_PACKAGES);
- **files** of the shared data folder (SHOW clips, spans of the ZeroEGGS Flirty take, for dev the spans of the
  ZeroEGGS training takes that training keeps for validation, the espeak sentences
  of ``speech/`` joined);
- **channel** variants: another voice's audio written at another sample rate and channel count and read
  back through the product's file reader (:func:`load_audio`), scored against the original's clean speech.
"""

from __future__ import annotations

import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import soundfile
import soxr

from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.programs import espeak, installed

HELD_OUT = "held-out"
DEV = "dev"
SPLITS = (HELD_OUT, DEV)

TEXTS: dict[str, tuple[str, ...]] = {
    "agent_booking": ("Thanks for calling, I can help you change your booking today.",
                      "First, could you tell me the name on the reservation?", "Great, I have found it.",
                      "Your flight leaves on Friday morning at nine fifteen, from gate twelve."),
    "agent_museum": ("The museum opens at ten and closes at six.",
                     "On weekends it stays open until eight in the evening.",
                     "Tickets are cheaper if you buy them online, and children under twelve get in for free."),
    "agent_plan": ("Let me explain how the new plan works.", "You pay once a month, and you can cancel at any time.",
                   "If you use more than your allowance, we simply send you a reminder.", "Nothing else changes."),
    "dev_class": ("Good morning, and welcome back.", "Yesterday we talked about the weather in the mountains.",
                  "Today I want to show you three photographs.", "Look closely at the clouds in the second one."),
    "dev_parcel": ("Your package is on its way.", "It should arrive between two and four this afternoon.",
                   "If nobody is home, the driver will leave it with a neighbour."),
    "de_train": ("Guten Tag, ich helfe Ihnen gern weiter.", "Ihr Zug fährt um halb neun von Gleis drei.",
                 "Bitte denken Sie an Ihre Fahrkarte.", "Ich wünsche Ihnen eine gute Reise."),
    "fr_order": ("Bonjour, merci de votre appel.", "Votre commande est partie ce matin.",
                 "Elle arrivera demain avant midi.", "Avez-vous une autre question ?"),
    "es_appointment": ("Hola, gracias por esperar.", "Su cita es el martes a las cuatro.",
                       "Si necesita cambiarla, llámenos antes del lunes.", "Que tenga un buen día."),
    "it_dev": ("Buongiorno, come posso aiutarla?", "Il ristorante apre alle sette di sera.",
               "Le consiglio di prenotare un tavolo.", "A presto."),
}
PAUSES_S = (0.9, 1.4, 0.7, 1.6)  # after sentence 1, 2, 3, … (cycled); none after the last


@dataclass(frozen=True)
class Espeak:
    voice: str  # espeak-ng -v (language + variant)
    speed: int  # words per minute (-s)
    pitch: int  # 0-99 (-p)
    text: str  # a key of TEXTS

    def argv(self, sentence: str, path: Path) -> list[str]:
        return [espeak(), "-v", self.voice, "-s", str(self.speed), "-p", str(self.pitch), "-w", str(path), sentence]


@dataclass(frozen=True)
class Flite:
    voice: str  # flite -voice (a built-in voice)
    stretch: float  # duration_stretch: 1.1 speaks a tenth slower
    text: str  # a key of TEXTS

    def argv(self, sentence: str, path: Path) -> list[str]:
        return [installed("flite"), "-voice", self.voice, "--setf", f"duration_stretch={self.stretch}", "-t",
                sentence, "-o", str(path)]


@dataclass(frozen=True)
class Channel:
    of: str  # the name of the voice whose audio is re-recorded
    rate: int  # Hz of the written file
    channels: int
    gain_db: float = 0.0


@dataclass(frozen=True)
class Voice:
    name: str
    group: str
    split: str
    espeak: Espeak | None = None
    flite: Flite | None = None
    files: tuple[str, ...] = ()  # under the shared data folder; several are joined with ``pauses_s``
    spans_s: tuple[tuple[float, float], ...] = ()  # the part (start, stop) of each file heard; none: whole files
    pauses_s: tuple[float, ...] = PAUSES_S  # the silences between files (cycled)
    channel: Channel | None = None


def _tts(name: str, group: str, split: str, voice: str, speed: int, pitch: int, text: str) -> Voice:
    return Voice(name, group, split, espeak=Espeak(voice, speed, pitch, text))


TTS_EN, TTS_OTHER, SPONTANEOUS, READ, CHANNEL, TTS_FLITE = (
    "tts english", "tts other languages", "spontaneous", "acted read speech", "resampled / stereo",
    "tts flite (another engine)")
FLIRTY = "zeggs/037_Flirty_1_x_1_0.wav"
ZEGGS_SPEECH, ZEGGS_NEUTRAL_0, ZEGGS_NEUTRAL_2 = (
    "zeggs/067_Speech_2_x_1_0.wav", "zeggs_upper/001_Neutral_0_x_1_0.wav", "zeggs_upper/003_Neutral_2_x_1_0.wav")
VOICES: tuple[Voice, ...] = (
    _tts("tts en-us f4 160 wpm", TTS_EN, HELD_OUT, "en-us+f4", 160, 60, "agent_booking"),
    _tts("tts en-gb-x-rp m5 140 wpm", TTS_EN, HELD_OUT, "en-gb-x-rp+m5", 140, 45, "agent_museum"),
    _tts("tts en-gb-scotland f1 185 wpm", TTS_EN, HELD_OUT, "en-gb-scotland+f1", 185, 40, "agent_plan"),
    _tts("tts en-029 klatt3 150 wpm", TTS_EN, HELD_OUT, "en-029+klatt3", 150, 50, "agent_booking"),
    _tts("tts en-us-nyc m7 200 wpm", TTS_EN, HELD_OUT, "en-us-nyc+m7", 200, 35, "agent_museum"),
    _tts("tts en-gb-x-gbcwmd Annie 165 wpm", TTS_EN, HELD_OUT, "en-gb-x-gbcwmd+Annie", 165, 70, "agent_plan"),
    _tts("tts de m3", TTS_OTHER, HELD_OUT, "de+m3", 155, 50, "de_train"),
    _tts("tts fr-fr f2", TTS_OTHER, HELD_OUT, "fr-fr+f2", 165, 55, "fr_order"),
    _tts("tts es klatt2", TTS_OTHER, HELD_OUT, "es+klatt2", 150, 45, "es_appointment"),
    Voice("show seth 1", SPONTANEOUS, HELD_OUT, files=("show/seth_98201-00_04_32-00_04_42.wav",)),
    Voice("show seth 2", SPONTANEOUS, HELD_OUT, files=("show/seth_98879-00_02_10-00_02_20.wav",)),
    Voice("show chemistry", SPONTANEOUS, HELD_OUT, files=("show/chemistry_68991-00_00_23-00_00_33.wav",)),
    Voice("flirty 0-30 s", READ, HELD_OUT, files=(FLIRTY,), spans_s=((0.0, 30.0),)),
    Voice("flirty 30-60 s", READ, HELD_OUT, files=(FLIRTY,), spans_s=((30.0, 60.0),)),
    Voice("flirty 60-90 s", READ, HELD_OUT, files=(FLIRTY,), spans_s=((60.0, 90.0),)),
    Voice("show seth 1 at 44.1 kHz stereo", CHANNEL, HELD_OUT, channel=Channel("show seth 1", 44100, 2)),
    Voice("tts en-us f4 at 48 kHz stereo, -12 dB", CHANNEL, HELD_OUT,
          channel=Channel("tts en-us f4 160 wpm", 48000, 2, -12.0)),
    Voice("flirty 30-60 s at 8 kHz", CHANNEL, HELD_OUT, channel=Channel("flirty 30-60 s", 8000, 1)),
    Voice("tts flite slt", TTS_FLITE, HELD_OUT, flite=Flite("slt", 1.0, "agent_booking")),
    Voice("tts flite rms, slower", TTS_FLITE, HELD_OUT, flite=Flite("rms", 1.15, "agent_museum")),
    Voice("tts flite awb", TTS_FLITE, HELD_OUT, flite=Flite("awb", 1.0, "agent_plan")),
    Voice("tts flite kal16 diphone, faster", TTS_FLITE, HELD_OUT, flite=Flite("kal16", 0.9, "agent_museum")),
    _tts("dev tts en-us m3 170 wpm", TTS_EN, DEV, "en-us+m3", 170, 50, "dev_class"),
    _tts("dev tts en-gb f5 150 wpm", TTS_EN, DEV, "en-gb+f5", 150, 65, "dev_parcel"),
    _tts("dev tts en-us klatt 180 wpm", TTS_EN, DEV, "en-us+klatt", 180, 50, "dev_class"),
    _tts("dev tts it f3", TTS_OTHER, DEV, "it+f3", 160, 55, "it_dev"),
    Voice("dev espeak sentences joined", TTS_EN, DEV,
          files=tuple(f"speech/tts_0{i}_{v}.wav" for i, v in
                      enumerate(("en-us", "en-us_f3", "en-gb", "en-us_m3", "en-us_f2", "en-us"), start=1))),
    Voice("dev show oliver 1", SPONTANEOUS, DEV, files=("show/oliver_214542-00_01_17-00_01_27.wav",)),
    Voice("dev show oliver 2", SPONTANEOUS, DEV, files=("show/oliver_216111-00_09_32-00_09_42.wav",)),
    Voice("dev show conan", SPONTANEOUS, DEV, files=("show/conan_115563-00_01_35-00_01_45.wav",)),
    Voice("dev show unknown", SPONTANEOUS, DEV, files=("show/unknown_116213-00_02_59-00_03_08.wav",)),
    # added on 2026-12-02 for choices on read speech: the spans of the ZeroEGGS takes that training keeps for
    # validation (the dataset cache's ``val`` segments, never trained on; the held-out Flirty take's actress), joined
    # by silences as long as the long pauses between lines of the training takes (median 7.0 s)
    Voice("dev zeggs validation spans", READ, DEV, files=(ZEGGS_SPEECH, ZEGGS_NEUTRAL_0, ZEGGS_NEUTRAL_2),
          spans_s=((51.633, 58.5), (91.067, 103.233), (97.5, 110.5)), pauses_s=(7.0, 5.6)),
)


@dataclass(frozen=True)
class VoiceAudio:
    voice: Voice
    heard: np.ndarray  # (N,) what the model hears, 16 kHz
    reference: np.ndarray  # (N,) the clean speech its motion is scored against


def join_with_pauses(parts: list[np.ndarray], pauses_s: tuple[float, ...] = PAUSES_S) -> np.ndarray:
    """Parts joined with the silences of ``pauses_s`` (cycled), none after the last: (N,) float32."""
    pieces = []
    for index, part in enumerate(parts):
        pieces.append(part.astype(np.float32))
        if index < len(parts) - 1:
            pieces.append(np.zeros(int(round(pauses_s[index % len(pauses_s)] * SAMPLE_RATE)), np.float32))
    return np.concatenate(pieces)


def spoken(spec: Espeak | Flite, sentence: str, folder: Path) -> np.ndarray:
    """One sentence spoken by the TTS engine of ``spec``, read back at 16 kHz: (N,)."""
    path = folder / "sentence.wav"
    subprocess.run(spec.argv(sentence, path), check=True, capture_output=True)
    return load_audio(path)


def rerecorded(audio: np.ndarray, channel: Channel, folder: Path) -> np.ndarray:
    """``audio`` written at ``channel``'s rate, channel count and gain, read back through the file reader: (N,)."""
    scaled = soxr.resample(audio, SAMPLE_RATE, channel.rate) * np.float32(10.0 ** (channel.gain_db / 20.0))
    path = folder / "channel.wav"
    soundfile.write(path, np.repeat(scaled[:, None], channel.channels, axis=1), channel.rate, subtype="PCM_16")
    return load_audio(path)


def _file_audio(voice: Voice, shared: Path) -> np.ndarray:
    missing = [name for name in voice.files if not (shared / name).is_file()]
    if missing:
        raise UserError(f"{shared / missing[0]}: not found (the voice '{voice.name}' of bench voices needs it)")
    parts = [load_audio(shared / name) for name in voice.files]
    if voice.spans_s:
        parts = [part[int(start * SAMPLE_RATE): int(stop * SAMPLE_RATE)]
                 for part, (start, stop) in zip(parts, voice.spans_s, strict=True)]
    return join_with_pauses(parts, voice.pauses_s)


def _clean_audio(voice: Voice, shared: Path, folder: Path) -> np.ndarray:
    spec = voice.espeak or voice.flite
    if spec is not None:
        return join_with_pauses([spoken(spec, sentence, folder) for sentence in TEXTS[spec.text]])
    return _file_audio(voice, shared)


def voice_audio(split: str, shared: Path) -> list[VoiceAudio]:
    """Every voice of ``split`` with what the model hears and the clean reference speech."""
    if split not in SPLITS:
        raise UserError(f"unknown voice split '{split}' (choose from {', '.join(SPLITS)})")
    by_name = {voice.name: voice for voice in VOICES}
    clean: dict[str, np.ndarray] = {}
    out = []
    with tempfile.TemporaryDirectory(prefix="gesturecast-voices-") as name:
        folder = Path(name)
        for voice in (v for v in VOICES if v.split == split):
            source = by_name[voice.channel.of] if voice.channel is not None else voice
            if source.name not in clean:
                clean[source.name] = _clean_audio(source, shared, folder)
            reference = clean[source.name]
            heard = reference if voice.channel is None else rerecorded(reference, voice.channel, folder)
            length = min(len(heard), len(reference))
            out.append(VoiceAudio(voice, heard[:length], reference[:length]))
    return out
