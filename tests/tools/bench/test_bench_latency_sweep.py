"""`gesturecast bench latency FILE --sweep`: every latency setting of a truncation model, the others' skipped."""

import json

import soundfile

from gesturecast.cli import main
from gesturecast.models.audio.files import SAMPLE_RATE

SECONDS = 3.0  # enough for the following score: 2 s left after 0.5 s skipped at each end, lags up to ±0.5 s


def test_sweep_reports_each_setting_of_a_truncation_model_and_skips_what_an_old_model_cannot(
        tiny_model, tiny_model_full_lookahead, speech_16k, tmp_path, capsys):
    audio = tmp_path / "speech.wav"
    soundfile.write(audio, speech_16k[: int(SECONDS * SAMPLE_RATE)], SAMPLE_RATE, subtype="FLOAT")
    out = tmp_path / "sweep"
    old = str(tiny_model_full_lookahead[1])
    args = ["bench", "latency", str(audio), "--sweep", "--model", str(tiny_model[1]), "--sweep-models", old,
            "--steps", "2", "--out", str(out), "--json"]
    assert main(args) == 0
    rows = json.loads(capsys.readouterr().out)["settings"]
    tiny = [row for row in rows if row["model"] == str(tiny_model[1])]
    assert [row["latency"] for row in tiny] == ["low", "balanced", "quality"]
    assert [row["lookahead_frames"] for row in tiny] == [0, 4, 8]
    budgets = [row["latency_budget_ms"] for row in tiny]
    assert budgets == sorted(budgets) and budgets[0] <= 250.0
    for row in tiny:
        assert row["frames"] == int(SECONDS * 30) and row["end_to_end_ms"]["p95"] > 0
        assert -1.0 <= row["following"]["r_best"] <= 1.0 and row["late_frames"] >= 0
    default = [row for row in rows if row["model"] == old]
    assert ["skipped" in row for row in default] == [True, True, False]
    assert "without look-ahead truncation" in default[0]["skipped"]
    assert (out / "latency_settings.md").read_text().count("\n") == 2 + len(rows)
    assert (out / "latency_settings.png").stat().st_size > 0
