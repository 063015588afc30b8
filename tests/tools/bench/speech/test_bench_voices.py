"""`gesturecast bench voices` end to end: the tiny model, a cache with 2 s held-out segments, cut voices."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import soundfile

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "models"))
from dataset_fixtures import make_zeggs_folder  # noqa: E402

from gesturecast.models.audio.files import SAMPLE_RATE, load_audio  # noqa: E402
from gesturecast.models.dataset.cache import build_dataset  # noqa: E402
from gesturecast.models.dataset.sources import zeggs_takes  # noqa: E402
from gesturecast.tools.bench.speech.voice_conditions import TRANSFORMS  # noqa: E402

pytest.importorskip("librosa")
pytest.importorskip("matplotlib")
PAIRED_FRAMES = 400  # 13.3 s: the held-out final 15 % is 2 s


def cut_voice(source: Path, target: Path, seconds: float) -> None:
    target.parent.mkdir(parents=True, exist_ok=True)
    soundfile.write(target, load_audio(source)[: int(seconds * SAMPLE_RATE)], SAMPLE_RATE)


@pytest.fixture(scope="module")
def voices_inputs(tmp_path_factory, shared_data) -> tuple[Path, Path]:
    root = tmp_path_factory.mktemp("voices")
    folder = make_zeggs_folder(root / "zeggs_src", shared_data / "zeggs", {"001_Neutral_0": "Neutral"}, PAIRED_FRAMES)
    build_dataset(zeggs_takes(folder), root / "dataset", progress=False)
    shared = root / "shared"
    cut_voice(shared_data / "show" / "seth_98201-00_04_32-00_04_42.wav", shared / "show" / "seth_1.wav", 2.5)
    cut_voice(shared_data / "show" / "oliver_214542-00_01_17-00_01_27.wav", shared / "show" / "oliver_1.wav", 2.5)
    cut_voice(shared_data / "zeggs" / "037_Flirty_1_x_1_0.wav", shared / "zeggs" / "037_Flirty_1_x_1_0.wav", 3.0)
    cut_voice(shared_data / "zeggs_upper" / "001_Neutral_0_x_1_0.wav", shared / "zeggs_upper" / "001_x.wav", 14.0)
    for name in ("tts_01_en-us.wav", "tts_03_en-gb.wav"):
        cut_voice(shared_data / "speech" / name, shared / "speech" / name, 2.5)
    return root / "dataset", shared


def test_bench_voices_scores_every_condition(tiny_model, voices_inputs, tmp_path):
    _, bundle = tiny_model
    cache, shared = voices_inputs
    out, plot = tmp_path / "voices.json", tmp_path / "voices.png"
    subprocess.run([sys.executable, "-m", "gesturecast.cli", "bench", "voices", "--bundle", str(bundle), "--cache",
                    str(cache), "--shared", str(shared), "--seeds", "0,1", "--json", str(out), "--plot", str(plot)],
                   check=True, capture_output=True, text=True)
    report = json.loads(out.read_text())
    conditions = report["conditions"]
    expected = {"original", *TRANSFORMS, "show held-out speakers", "flirty", "espeak single", "espeak joined"}
    assert set(conditions) == expected
    assert conditions["show held-out speakers"]["files"] == 1  # oliver is not a held-out speaker
    assert conditions["original"]["ratio_to_original"] == 1.0
    assert conditions["original"]["files"] == 2  # the cached take's test segment and zeggs_upper's final 15 %
    for name in TRANSFORMS:
        row = conditions[name]
        assert row["rows"] == 4 and np.isfinite(row["chance"])
        if row["r"] is not None and conditions["original"]["r"] > 0:
            assert row["ratio_to_original"] == pytest.approx(row["r"] / conditions["original"]["r"], abs=2e-3)
    assert conditions["espeak joined"]["rest"] is not None  # 1.5 s pauses
    assert report["real_motion"]["original"]["rows"] == 1
    assert plot.stat().st_size > 10_000
