"""`gesturecast gestures build | list`: the table, the JSON, a quick build, no torch, one-line errors."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from gesturecast.cli import main
from gesturecast.errors import USER_ERROR_EXIT_CODE
from gesturecast.models.motion.motion_features import features_to_motion
from gesturecast.models.motion.retarget import motion_to_bvh
from gesturecast.realtime.gestures import lexicon as gl
from gesturecast.tools.gestures.build import GESTURE_NAMES

RAW_CACHE = Path(__file__).resolve().parents[2] / ".cache" / "raw"  # where `gesturecast data build` unpacks
NO_TORCH = "import sys; sys.modules['torch'] = None; from gesturecast.cli import main; sys.exit(main({argv!r}))"


def run_cli(argv: list[str]) -> int:
    try:
        return main(argv)
    except SystemExit as stop:
        return int(stop.code)


def test_list_says_what_each_speech_act_plays_then_every_gesture_by_what_it_shows(capsys):
    assert run_cli(["gestures", "list"]) == 0
    text = capsys.readouterr().out
    acts, gestures = text.split("\n\n")
    act_rows = {line.split()[0]: line.split()[1] for line in acts.splitlines()[1:-1]}
    assert act_rows == {"greeting": "wave", "thanks": "bow", "farewell": "wave-right", "celebration": "raise-both",
                        "presenting": "guide", "calling": "call"}
    assert "bye, goodbye" in acts.splitlines()[3] and acts.splitlines()[-1].startswith("on request only")
    assert "hand-up" in acts.splitlines()[-1]
    lines = gestures.splitlines()
    assert lines[0].split() == ["name", "parts", "duration", "stroke", "styles", "shows"]
    rows = {line.split()[0]: line for line in lines[1:len(GESTURE_NAMES) + 1]}
    assert set(rows) == set(GESTURE_NAMES)
    assert "arms+torso" in rows["bow"] and "bows from the waist" in rows["bow"] and "neutral" in rows["bow"]
    assert rows["hand-up"].endswith("holds a hand up at shoulder height")
    assert "CC BY-NC 4.0" in lines[-1]


def test_list_json_matches_the_lexicon(capsys):
    assert run_cli(["gestures", "list", "--json"]) == 0
    listed = json.loads(capsys.readouterr().out)
    shipped = gl.load_lexicon()
    assert listed["speech_acts"]["farewell"]["plays"] == "wave-right"
    assert "goodbye" in listed["speech_acts"]["farewell"]["phrases"]
    assert [row["name"] for row in listed["gestures"]] == list(shipped.entries)
    wave = listed["gestures"][0]
    assert set(wave) >= {"name", "parts", "duration", "stroke", "styles", "triggers", "variants"}
    assert wave["stroke"] == pytest.approx(shipped["wave"].stroke_time, abs=1e-3) and wave["stroke"] > 0
    assert wave["stroke"] < wave["duration"]


def test_list_reads_a_user_folder(tmp_path, capsys):
    features = gl.load_lexicon()["bow"].variant().features.astype(np.float64)
    motion_to_bvh(features_to_motion(features), tmp_path / "nod.bvh")
    (tmp_path / gl.USER_MAPPING_FILE).write_text(json.dumps(
        {"nod": {"clip": "nod.bvh", "triggers": ["indeed"], "parts": ["torso"], "stroke": 1.0}}))
    assert run_cli(["gestures", "list", "--lexicon", str(tmp_path), "--json"]) == 0
    (row,) = json.loads(capsys.readouterr().out)["gestures"]
    assert (row["name"], row["parts"], row["triggers"], row["stroke"]) == ("nod", ["torso"], ["indeed"], 1.0)


def test_list_needs_no_torch(tmp_path):
    result = subprocess.run([sys.executable, "-c", NO_TORCH.format(argv=["gestures", "list"])], capture_output=True,
                            text=True, timeout=120, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "wave" in result.stdout


def test_a_quick_build_writes_a_lexicon_without_torch(shared_data, tmp_path):
    """One take per gesture and style (about 50 takes), in a process where importing torch fails."""
    out = tmp_path / "lexicon"
    argv = ["gestures", "build", "--shared", str(shared_data), "--out", str(out), "--raw-cache", str(RAW_CACHE),
            "--per-style", "1", "--styles", "2"]
    result = subprocess.run([sys.executable, "-c", NO_TORCH.format(argv=argv)], capture_output=True, text=True,
                            timeout=300, cwd=tmp_path)
    assert result.returncode == 0, result.stderr[-2000:]
    summary = json.loads(result.stdout.splitlines()[-1])
    assert summary["gestures"] == len(GESTURE_NAMES) and summary["total_bytes"] < 2_000_000
    assert "gesture takes" in result.stderr  # the progress bar
    built = gl.load_lexicon(out)
    assert set(built.entries) == set(GESTURE_NAMES)
    assert all(len(entry.styles) <= 2 and entry.styles[0] == "neutral" for entry in built)


@pytest.mark.parametrize(("argv", "expected"), [
    (["gestures", "build", "--shared", "{tmp}", "--out", "{tmp}/out"], "no bandai/ folder"),
    (["gestures", "build", "--shared", "{tmp}", "--per-style", "0"], "--per-style must be at least 1"),
    (["gestures", "build", "--shared", "{tmp}", "--takes", "0"], "--takes must be at least 1"),
    (["gestures", "list", "--lexicon", "{tmp}"], "holds neither lexicon.json"),
])
def test_bad_input_is_one_line(argv, expected, tmp_path, capsys):
    code = run_cli([word.format(tmp=tmp_path) for word in argv])
    error = capsys.readouterr().err.strip()
    assert code == USER_ERROR_EXIT_CODE, error
    assert error.startswith("gesturecast gestures: error: ") and "\n" not in error and expected in error
    assert not (tmp_path / "out").exists()
