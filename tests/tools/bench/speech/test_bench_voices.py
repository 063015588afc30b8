"""`gesturecast bench voices` end to end: the tiny model, a cache with 2 s held-out segments, cut voices."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
import soundfile

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "models"))
from dataset_fixtures import make_zeggs_folder  # noqa: E402

from gesturecast.cli import main  # noqa: E402
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio  # noqa: E402
from gesturecast.models.dataset.cache import build_dataset  # noqa: E402
from gesturecast.models.dataset.sources import show_takes, zeggs_takes  # noqa: E402
from gesturecast.tools.bench.speech.voice_conditions import (  # noqa: E402
    TRANSFORMS,
    recorded_motion,
    voice_set_cases,
)
from gesturecast.tools.bench.speech.voice_set import DEV, VOICES  # noqa: E402

pytest.importorskip("librosa")
pytest.importorskip("matplotlib")
PAIRED_FRAMES = 400  # 13.3 s: the held-out final 15 % is 2 s
needs_espeak = pytest.mark.skipif(shutil.which("espeak-ng") is None, reason="espeak-ng is not installed")


def cut_voice(source: Path, target: Path, seconds: float, start_s: float = 0.0) -> None:
    """``seconds`` of ``source`` from ``start_s``, written at the same place of ``target`` (silence before it)."""
    target.parent.mkdir(parents=True, exist_ok=True)
    start = int(start_s * SAMPLE_RATE)
    kept = load_audio(source)[start: start + int(seconds * SAMPLE_RATE)]
    soundfile.write(target, np.concatenate([np.zeros(start, np.float32), kept]), SAMPLE_RATE)


@pytest.fixture(scope="module")
def voices_inputs(tmp_path_factory, shared_data) -> tuple[Path, Path, Path]:
    """(the dataset cache, a shared folder for the transforms, one for the dev voices: 2.5 s of each file they hear,
    in its place)."""
    root = tmp_path_factory.mktemp("voices")
    folder = make_zeggs_folder(root / "zeggs_src", shared_data / "zeggs", {"001_Neutral_0": "Neutral"}, PAIRED_FRAMES)
    build_dataset(zeggs_takes(folder), root / "dataset", progress=False)
    transforms, dev = root / "shared_transforms", root / "shared_dev"
    cut_voice(shared_data / "zeggs_upper" / "001_Neutral_0_x_1_0.wav", transforms / "zeggs_upper" / "001_x.wav", 14.0)
    for voice in (voice for voice in VOICES if voice.split == DEV):
        starts = [start for start, _ in voice.spans_s] or [0.0] * len(voice.files)
        for name, start in zip(voice.files, starts, strict=True):
            cut_voice(shared_data / name, dev / name, 2.5, start)
    return root / "dataset", transforms, dev


def run_voices(bundle: Path, cache: Path, shared: Path, out: Path, *options: str) -> dict:
    """``gesturecast bench voices`` run by the CLI's main in this process (the process boundary is not what these
    tests check)."""
    assert main(["bench", "voices", "--bundle", str(bundle), "--cache", str(cache), "--shared", str(shared),
                 "--seeds", "0,1", "--json", str(out), *options]) == 0
    return json.loads(out.read_text())


def test_bench_voices_scores_every_transform(tiny_model, voices_inputs, tmp_path):
    _, bundle = tiny_model
    cache, shared, _ = voices_inputs
    plot = tmp_path / "voices.png"
    report = run_voices(bundle, cache, shared, tmp_path / "voices.json", "--set", "transforms", "--plot", str(plot))
    conditions = report["conditions"]
    assert set(conditions) == {"original", *TRANSFORMS}
    assert conditions["original"]["ratio_to_original"] == 1.0
    assert conditions["original"]["files"] == 2  # the cached take's test segment and zeggs_upper's final 15 %
    for name in TRANSFORMS:
        row = conditions[name]
        assert row["rows"] == 4 and np.isfinite(row["chance"])
        if row["r"] is not None and conditions["original"]["r"] > 0:
            assert row["ratio_to_original"] == pytest.approx(row["r"] / conditions["original"]["r"], abs=2e-3)
    assert report["real_motion"]["original"]["rows"] == 1
    assert plot.stat().st_size > 10_000


@needs_espeak
def test_bench_voices_scores_each_voice_group_against_chance(tiny_model, voices_inputs, tmp_path):
    _, bundle = tiny_model
    cache, _, shared = voices_inputs
    report = run_voices(bundle, cache, shared, tmp_path / "dev.json", "--set", "dev", "--guidance", "1")
    dev = [voice for voice in VOICES if voice.split == DEV]
    assert report["set"] == "dev" and report["guidance"] == 1.0
    groups = report["conditions"]
    assert set(groups) == {voice.group for voice in dev}
    assert sum(group["files"] for group in groups.values()) == len(dev)
    for group in groups.values():
        assert group["rows"] == 2 * group["files"] and np.isfinite(group["chance"])
        assert group["margin"] == pytest.approx(group["r"] - group["chance"], abs=2e-4)
    assert groups["tts english"]["rest"] is not None  # espeak-ng sentences joined with ≥ 0.7 s pauses
    means = [groups[name]["margin"] for name in groups]
    assert report["overall"]["margin"] == pytest.approx(np.mean(means), abs=2e-4)


@needs_espeak
def test_whole_show_recordings_carry_their_cached_real_motion(shared_data, tmp_path):
    build_dataset(show_takes(shared_data / "show"), tmp_path / "cache", progress=False)
    motion = recorded_motion(tmp_path / "cache")
    seth = motion["show/seth_98201-00_04_32-00_04_42.wav"]
    assert seth.ndim == 3 and seth.shape[0] == 300 and seth.shape[2] == 3  # (T, J, 3): 10 s at 30 fps
    cases = voice_set_cases(DEV, shared_data, tmp_path / "cache")
    carrying = {case.voice for case in cases if case.positions is not None}
    assert carrying == {voice.name for voice in VOICES if voice.split == DEV and voice.files
                        and voice.files[0].startswith("show/")}
    assert recorded_motion(tmp_path / "no_cache") == {}
