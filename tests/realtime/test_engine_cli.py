"""The user commands: `generate` and `live --input` give the same motion; bad flags are one-line errors."""

import json

import numpy as np
import pytest
import soundfile

from gesturecast.cli import main
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.motion.bvh import read_bvh
from gesturecast.models.motion.retarget import load_motion_file
from gesturecast.models.motion.skeleton import CANONICAL, CANONICAL_WITH_HANDS


@pytest.fixture(scope="module")
def speech(tmp_path_factory, shared_data):
    audio = load_audio(shared_data / "speech" / "tts_01_en-us.wav")[: 2 * SAMPLE_RATE]
    path = tmp_path_factory.mktemp("cli") / "speech.wav"
    soundfile.write(path, audio, SAMPLE_RATE, subtype="PCM_16")
    return path


def test_generate_equals_live_input_with_the_same_seed(tiny_model, speech, tmp_path):
    """The live engine read as fast as it can (a paced run that falls behind degrades its late latents on purpose,
    docs/latency.md) makes exactly generate's poses."""
    bundle = str(tiny_model[1])
    common = ["--model", bundle, "--seed", "3", "--steps", "2", "--style", "old"]
    assert main(["generate", str(speech), "-o", str(tmp_path / "gen.bvh"), "--json", str(tmp_path / "gen.json"),
                 *common]) == 0
    assert main(["live", "--input", str(speech), "--pace", "fast", "--bvh", str(tmp_path / "live.bvh"), *common]) == 0
    generated, live = read_bvh(tmp_path / "gen.bvh"), read_bvh(tmp_path / "live.bvh")
    assert generated.motion.shape == live.motion.shape == (60, generated.motion.shape[1])
    np.testing.assert_allclose(generated.motion, live.motion, atol=1e-6)
    stream = json.loads((tmp_path / "gen.json").read_text())
    assert len(stream["frames"]) == 60 and len(stream["frames"][0]["rotations"]) == len(stream["bones"])


def test_ddpm_sampler_runs_all_steps_on_the_same_model(tiny_model, speech, tmp_path):
    out = tmp_path / "ddpm.bvh"
    assert main(["generate", str(speech), "-o", str(out), "--model", str(tiny_model[1]), "--sampler", "ddpm"]) == 0
    assert np.isfinite(read_bvh(out).motion).all()


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--style", "sparkly"], "unknown style"),
        (["--lookahead", "9"], "past this model's δa = 8"),
        (["--model", "/nonexistent"], "no model bundle"),
    ],
)
def test_bad_generation_flags_are_one_line_errors(tiny_model, speech, tmp_path, capsys, flags, message):
    args = ["generate", str(speech), "-o", str(tmp_path / "x.bvh"), "--model", str(tiny_model[1]), *flags]
    assert main(args) == 2
    error = capsys.readouterr().err.strip()
    assert message in error and "\n" not in error
    assert not (tmp_path / "x.bvh").exists()


def test_live_without_outputs_says_which_flags_to_use(tiny_model, speech, capsys):
    assert main(["live", "--input", str(speech), "--model", str(tiny_model[1])]) == 2
    assert "--vmc" in capsys.readouterr().err


BLOCK_TRAINING_PACKAGES = """
import importlib.abc, sys
class Blocker(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name.split(".")[0] in {"torch", "onnx", "matplotlib", "librosa"}:
            raise ModuleNotFoundError(name)
sys.meta_path.insert(0, Blocker())
from gesturecast.cli import main
sys.exit(main(sys.argv[1:]))
"""


def test_the_cli_and_generate_run_without_training_packages(tiny_model, speech, tmp_path):
    """A VTuber installs no torch: every command parses, and the live/offline path runs, with torch,
    onnx, matplotlib and librosa unimportable."""
    import subprocess
    import sys

    out = tmp_path / "no_torch.bvh"
    for argv in (["--help"], ["generate", str(speech), "-o", str(out), "--model", str(tiny_model[1])]):
        result = subprocess.run([sys.executable, "-c", BLOCK_TRAINING_PACKAGES, *argv], capture_output=True,
                                text=True, timeout=300)
        assert result.returncode == 0, result.stderr[-2000:]
    assert read_bvh(out).motion.shape[0] == 60


def test_live_fast_pace_reports_no_uptime_as_latency_and_no_false_misses(tiny_model, speech, tmp_path, capsys):
    """`live --pace fast` sends each frame as soon as it exists: its stream-time presentation times are not on
    the clock, so the summary shows no end-to-end time (it was the machine's uptime) and no deadline misses."""
    out = tmp_path / "fast.bvh"
    assert main(["live", "--input", str(speech), "--pace", "fast", "--bvh", str(out), "--model", str(tiny_model[1]),
                 "--steps", "2"]) == 0
    summary = capsys.readouterr().out.strip().splitlines()[-1]
    assert "end-to-end n/a (unpaced)" in summary
    assert "deadline misses 0 | late releases 0" in summary
    assert read_bvh(out).motion.shape[0] == 60


def test_generate_writes_fingers_that_read_back_as_the_body_or_with_hands(tiny_model, speech, tmp_path):
    """The BVH and JSON carry 52 joints (22 body + 30 finger); the loader gives the model's 22-joint Motion,
    or the fingers too with keep_hands (what `render` draws)."""
    out, stream_json = tmp_path / "hands.bvh", tmp_path / "hands.json"
    assert main(["generate", str(speech), "-o", str(out), "--json", str(stream_json), "--model", str(tiny_model[1]),
                 "--steps", "2"]) == 0
    data = read_bvh(out)
    assert sorted(data.names) == sorted(CANONICAL_WITH_HANDS.names) and "RightLittleDistal" in data.names
    assert data.names[data.names.index("LeftHand") + 1] == "LeftThumbProximal"  # depth-first: fingers follow
    assert json.loads(stream_json.read_text())["bones"] == list(CANONICAL_WITH_HANDS.names)
    body = load_motion_file(out)
    assert body.skeleton.names == CANONICAL.names and body.num_frames == data.num_frames
    with_hands = load_motion_file(out, keep_hands=True)
    assert with_hands.skeleton is CANONICAL_WITH_HANDS
    in_file_order = with_hands.rotations[:, [CANONICAL_WITH_HANDS.index(n) for n in data.names]]  # (T, J, 4)
    same_rotation = np.abs((in_file_order * data.local_rotations()).sum(axis=-1))  # (T, J) |q·q'| = 1
    np.testing.assert_allclose(same_rotation, 1.0, atol=1e-6)
    np.testing.assert_allclose(with_hands.positions()[:, : CANONICAL.num_joints], body.positions(), atol=1e-3)


def test_live_bvh_at_60_fps_has_a_60_fps_frame_time(tiny_model, speech, tmp_path):
    """--fps 60 upsamples the stream; the recorder's Frame Time says so (it was always 1/30: half speed)."""
    out = tmp_path / "sixty.bvh"
    assert main(["live", "--input", str(speech), "--pace", "fast", "--fps", "60", "--bvh", str(out),
                 "--model", str(tiny_model[1]), "--steps", "2"]) == 0
    recorded = read_bvh(out)
    assert recorded.fps == pytest.approx(60.0, rel=1e-4)
    assert recorded.num_frames / recorded.fps == pytest.approx(2.0, abs=2 / 60)  # plays for as long as the speech


@pytest.mark.parametrize("mode, names", [("vrm1", ["aa", "ih", "ou", "ee", "oh"]), ("off", None)])
def test_generate_json_carries_the_viseme_names_and_weights(tiny_model, speech, tmp_path, mode, names):
    out, stream_json = tmp_path / "a.bvh", tmp_path / "a.json"
    assert main(["generate", str(speech), "-o", str(out), "--json", str(stream_json), "--model", str(tiny_model[1]),
                 "--steps", "1", "--lipsync", mode]) == 0
    stream = json.loads(stream_json.read_text())
    assert stream.get("visemes") == names
    weights = [frame.get("visemes") for frame in stream["frames"]]
    if names is None:
        assert weights == [None] * len(weights)
    else:
        assert all(len(w) == len(names) and min(w) >= 0.0 and sum(w) <= 1.0 + 1e-3 for w in weights)
        assert max(sum(w) for w in weights) > 0.3  # the speech opens the mouth
