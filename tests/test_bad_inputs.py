"""Every bad input reaches the user as one line (``gesturecast <cmd>: error: ...``), exit code 2, no traceback.

The table below is the whole test: one row per bad input, run through the real CLI ``main()``. A row
is a command line with placeholders, optionally a file maker that writes the bad file, and a substring
the error line must contain. To add a case, add a row (and, for a new kind of bad file, a maker).

Placeholders: ``{speech}`` 1 s of real speech, ``{model}`` the bundled default model, ``{bundle}`` a
copy of it that the row's maker may corrupt, ``{file}`` the file the row's maker wrote, ``{out}`` an
output path in the test's folder (which must not exist afterwards).
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import soundfile

from gesturecast.cli import main
from gesturecast.errors import USER_ERROR_EXIT_CODE
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.motion.bvh import write_bvh
from gesturecast.models.motion.canonical_bvh import canonical_bvh_data
from gesturecast.models.motion.rotations import quat_identity
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.settings import DEFAULT_MODEL_DIR

REPO_ROOT = Path(__file__).resolve().parents[1]
SAMPLE_SPEECH = REPO_ROOT / "gesturecast" / "samples" / "sample_speech.wav"
SMPLX_POSE_DIM = 165
NPZ_FRAMES = 10
DEEP_NESTING = 5000  # far past Python's recursion limit

Maker = Callable[[Path], Path]  # (folder of the row) -> the bad file it wrote ({file} or the {bundle} folder)


# ---- makers of bad files -------------------------------------------------------------------------
def bvh_text(frame_time: str = "0.0333333", values: str = "0 90 0 0 0 0", joints: int = 1,
             offset: str = "0 0 0") -> str:
    """A small BVH: a chain of ``joints`` nested joints (the root at ``offset``), one frame."""
    opening = "".join(f"JOINT J{i}\n{{\nOFFSET 0 1 0\nCHANNELS 0\n" for i in range(1, joints))
    closing = "}\n" * (joints - 1)
    return (f"HIERARCHY\nROOT Hips\n{{\nOFFSET {offset}\nCHANNELS 6 Xposition Yposition Zposition "
            f"Zrotation Xrotation Yrotation\n{opening}{closing}}}\nMOTION\nFrames: 1\nFrame Time: {frame_time}\n"
            f"{values}\n")


def write_bvh_file(**kwargs: str | int) -> Maker:
    def make(folder: Path) -> Path:
        path = folder / "clip.bvh"
        path.write_text(bvh_text(**kwargs))
        return path

    return make


def write_flat_skeleton(folder: Path) -> Path:
    """A canonical-skeleton BVH whose OFFSETs and End Sites are all zero: nothing to scale the clip by."""
    data = canonical_bvh_data(quat_identity((2, CANONICAL.num_joints)), np.zeros((2, 3)), 30.0)
    data.offsets[:] = 0.0
    data.end_sites = {joint: np.zeros(3) for joint in data.end_sites}
    path = folder / "clip.bvh"
    write_bvh(data, path)
    return path


def write_long_token(folder: Path) -> Path:
    """A token file of 5000 characters: more than a token file may hold (a device such as /dev/zero never ends)."""
    path = folder / "token"
    path.write_text("t" * 5000)
    return path


def write_npz(**arrays: object) -> Maker:
    """An SMPL-X .npz with zero poses and trans, overridden or extended by ``arrays``."""

    def make(folder: Path) -> Path:
        content = {"poses": np.zeros((NPZ_FRAMES, SMPLX_POSE_DIM)), "trans": np.zeros((NPZ_FRAMES, 3)), **arrays}
        path = folder / "clip.npz"
        np.savez(path, **content)
        return path

    return make


def corrupt_bundle(change: Callable[[Path], None]) -> Maker:
    """A copy of the default bundle in ``folder/bundle`` with ``change`` applied to the copy."""

    def make(folder: Path) -> Path:
        bundle = folder / "bundle"
        shutil.copytree(DEFAULT_MODEL_DIR, bundle)
        change(bundle)
        return bundle

    return make


def truncate_onnx(bundle: Path) -> None:
    path = bundle / "denoiser.onnx"
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 3])


def garbage_manifest(bundle: Path) -> None:
    (bundle / "model.json").write_bytes(b"\x00\xff not json {")


def edit_manifest(edit: Callable[[dict], None]) -> Callable[[Path], None]:
    def change(bundle: Path) -> None:
        manifest = json.loads((bundle / "model.json").read_text())
        edit(manifest)
        (bundle / "model.json").write_text(json.dumps(manifest))

    return change


def nan_motion_mean(manifest: dict) -> None:
    manifest["motion_stats"]["mean"][0] = float("nan")  # json.dumps writes a bare NaN, which json.loads reads


def missing_denoiser(manifest: dict) -> None:
    del manifest["denoiser"]


# ---- the table -----------------------------------------------------------------------------------
@dataclass(frozen=True)
class BadInput:
    argv: str
    expected: str
    make: Maker | None = None


GENERATE = "generate {speech} -o {out} --model {model}"
RENDER = "render {file} -o {out}"
BAD_INPUTS: dict[str, BadInput] = {
    # flags: numbers out of range or not finite
    "steps 0": BadInput(f"{GENERATE} --steps 0", "--steps: must be an integer from 1 to 1000"),
    "threads 0": BadInput(f"{GENERATE} --threads 0", "--threads: must be an integer from 1 to 64"),
    "seed -1": BadInput(f"{GENERATE} --seed -1", "--seed: must be an integer from 0 to 4294967295"),
    "margin nan": BadInput(f"{GENERATE} --margin-ms nan", "--margin-ms: must be a finite number ≥ 0"),
    "margin inf": BadInput(f"{GENERATE} --margin-ms inf", "--margin-ms: must be a finite number"),
    "guidance inf": BadInput(f"{GENERATE} --guidance inf", "--guidance: must be a finite number"),
    "audio guidance nan": BadInput(f"{GENERATE} --audio-guidance nan", "--audio-guidance: must be a finite"),
    "gamma nan": BadInput(f"{GENERATE} --gamma nan", "--gamma: must be a finite number"),
    "lookahead -1": BadInput(f"{GENERATE} --lookahead -1", "--lookahead: must be an integer from 0 to 64"),
    "latency unknown": BadInput(f"{GENERATE} --latency fast", "--latency: invalid choice"),
    # flags: numbers past their upper bound (each would hang, exhaust memory or make every pose non-finite)
    "smoothing 1000": BadInput(f"{GENERATE} --smoothing 1000", "--smoothing: must be an integer from 0 to 15"),
    "threads 100000": BadInput(f"{GENERATE} --threads 100000", "--threads: must be an integer from 1 to 64"),
    "steps 100000": BadInput(f"{GENERATE} --steps 100000", "--steps: must be an integer from 1 to 1000"),
    "margin 1e12": BadInput(f"{GENERATE} --margin-ms 1e12", "--margin-ms: must be a finite number ≥ 0 and ≤ 2000"),
    "guidance 1e308": BadInput(f"{GENERATE} --guidance 1e308", "--guidance: must be a finite number ≥ 0 and ≤ 10"),
    # outputs: the suffix picks the format, and an unknown one is refused rather than written as BVH text
    "output glb": BadInput("generate {speech} -o {out}.glb", "name a .bvh, .vrma or .json file"),
    "output mp4": BadInput("generate {speech} -o {out}.mp4", "name a .bvh, .vrma or .json file"),
    "output without suffix": BadInput("generate {speech} -o {out}.d/take", "name a .bvh, .vrma or .json file"),
    "vrma not vrma": BadInput("generate {speech} -o {out} --vrma {out}.glb", "--vrma"),
    "ws port 70000": BadInput("live --input {speech} --ws 70000", "--ws: must be an integer from 0 to 65535"),
    "serve port 70000": BadInput("serve --port 70000", "--port: must be an integer from 0 to 65535"),
    "serve token file 5000 bytes": BadInput("serve --port 0 --token-file {file}", "holds more than 4 KiB",
                                            write_long_token),
    "live token file 5000 bytes": BadInput("live --input {speech} --ws 0 --token-file {file}", "holds more than 4 KiB",
                                           write_long_token),
    "demo audio missing": BadInput("demo --out {out}.d --audio {out}.missing.wav", "missing.wav"),
    "block size 0": BadInput("live --input {speech} --bvh {out} --block-size 0", "--block-size: must be an integer"),
    "render start nan": BadInput("render {speech} -o {out} --start nan", "--start: must be a finite number ≥ 0"),
    "render seconds 0": BadInput("render {speech} -o {out} --seconds 0", "--seconds: must be a finite number > 0"),
    # model bundles
    "truncated onnx": BadInput(f"{GENERATE.replace('{model}', '{bundle}')}", "not a valid ONNX model",
                               corrupt_bundle(truncate_onnx)),
    "garbage model.json": BadInput(f"{GENERATE.replace('{model}', '{bundle}')}", "not a readable model manifest",
                                   corrupt_bundle(garbage_manifest)),
    "model.json without denoiser": BadInput(f"{GENERATE.replace('{model}', '{bundle}')}", "is malformed",
                                            corrupt_bundle(edit_manifest(missing_denoiser))),
    "NaN statistics": BadInput(f"{GENERATE.replace('{model}', '{bundle}')}", "NaN or infinite numbers in motion_stats",
                               corrupt_bundle(edit_manifest(nan_motion_mean))),
    # motion files: as render input and as motion style prompt
    "BVH nested 5000 deep": BadInput(RENDER, "nested more than", write_bvh_file(joints=DEEP_NESTING)),
    "BVH Frame Time inf": BadInput(RENDER, "Frame Time must be a positive finite", write_bvh_file(frame_time="inf")),
    "BVH NaN value": BadInput(RENDER, "NaN or infinite", write_bvh_file(values="0 nan 0 0 0 0")),
    "NPZ fps 0": BadInput(RENDER, "mocap_frame_rate must be a positive", write_npz(mocap_frame_rate=0.0)),
    "NPZ fps negative": BadInput(RENDER, "mocap_frame_rate must be a positive", write_npz(mocap_frame_rate=-30.0)),
    "NPZ fps array": BadInput(RENDER, "mocap_frame_rate must be one number",
                              write_npz(mocap_frame_rate=np.array([30.0, 60.0]))),
    "NPZ inf trans": BadInput(RENDER, "NaN or infinite", write_npz(trans=np.full((NPZ_FRAMES, 3), np.inf))),
    "motion prompt with NaN": BadInput(f"{GENERATE} --motion-prompt {{file}}", "NaN or infinite",
                                       write_bvh_file(values="0 90 0 nan 0 0")),
    "motion prompt NPZ inf": BadInput(f"{GENERATE} --motion-prompt {{file}}", "NaN or infinite",
                                      write_npz(poses=np.full((NPZ_FRAMES, SMPLX_POSE_DIM), -np.inf))),
    "motion prompt NPZ arm pose 1e308": BadInput(f"{GENERATE} --motion-prompt {{file}}",
                                                 "an SMPL-X pose value of 1e+308 rad is beyond the supported",
                                                 write_npz(poses=np.pad(np.full((NPZ_FRAMES, 3), 1e308),
                                                                        ((0, 0), (60, SMPLX_POSE_DIM - 63))))),
    # seed motions and motion prompts: non-finite or absurd lengths (they reached every pose of every stream)
    "seed motion zero OFFSETs": BadInput(f"{GENERATE} --seed-motion {{file}}", "zero OFFSET on LeftUpperLeg",
                                         write_flat_skeleton),
    "motion prompt zero OFFSETs": BadInput(f"{GENERATE} --motion-prompt {{file}}", "the legs have no length",
                                           write_flat_skeleton),
    "seed motion OFFSET nan": BadInput(f"{GENERATE} --seed-motion {{file}}", "joint 'Hips' OFFSET holds a NaN",
                                       write_bvh_file(offset="0 nan 0")),
    "seed motion root 1e30": BadInput(f"{GENERATE} --seed-motion {{file}}", "Yposition value 1e+30 is beyond",
                                      write_bvh_file(values="0 1e30 0 0 0 0")),
    "seed motion NPZ trans 1e30": BadInput(f"{GENERATE} --seed-motion {{file}}", "the Hips reach",
                                           write_npz(trans=np.full((NPZ_FRAMES, 3), 1e30))),
    "motion prompt OFFSET inf": BadInput(f"{GENERATE} --motion-prompt {{file}}", "OFFSET holds a NaN or infinite",
                                         write_bvh_file(offset="inf 0 0")),
}


@pytest.fixture(scope="module")
def speech(tmp_path_factory) -> Path:
    """One second of the bundled sample speech."""
    path = tmp_path_factory.mktemp("bad_inputs") / "speech.wav"
    soundfile.write(path, load_audio(SAMPLE_SPEECH)[:SAMPLE_RATE], SAMPLE_RATE, subtype="PCM_16")
    return path


def run_cli(argv: list[str]) -> int:
    """``main(argv)``; argparse's own errors exit through SystemExit, which is turned into the exit code."""
    try:
        return main(argv)
    except SystemExit as stop:
        return int(stop.code)


@pytest.mark.parametrize("case", BAD_INPUTS.values(), ids=BAD_INPUTS.keys())
def test_bad_input_is_one_line_with_exit_code_2(case: BadInput, speech: Path, tmp_path: Path, capsys):
    made = case.make(tmp_path) if case.make is not None else tmp_path / "unused"
    out = tmp_path / "out.gif" if case.argv.startswith("render") else tmp_path / "out.bvh"
    argv = case.argv.format(speech=speech, model=DEFAULT_MODEL_DIR, bundle=made, file=made, out=out).split()
    assert_one_line_error(argv, case.expected, out, capsys)


def assert_one_line_error(argv: list[str], expected: str, out: Path, capsys) -> None:
    code = run_cli(argv)
    error = capsys.readouterr().err.strip()
    assert code == USER_ERROR_EXIT_CODE, error
    assert error.startswith(f"gesturecast {argv[0]}: error: "), error
    assert "\n" not in error and "Traceback" not in error
    assert expected in error
    assert not out.exists()


def test_latency_low_on_a_model_without_lookahead_truncation_is_one_line(tiny_model_full_lookahead, speech,
                                                                          tmp_path, capsys):
    out = tmp_path / "out.bvh"
    argv = f"{GENERATE} --latency low".format(speech=speech, model=tiny_model_full_lookahead[1], out=out).split()
    assert_one_line_error(argv, "trained without look-ahead truncation", out, capsys)


def test_bad_flag_from_the_installed_script_is_one_line(tmp_path):
    """The real console script in a subprocess (logging configured as for a user): one stderr line."""
    import subprocess
    import sys

    result = subprocess.run([sys.executable, "-m", "gesturecast.cli", "generate", "x.wav", "-o", str(tmp_path / "o"),
                             "--guidance", "inf"], capture_output=True, text=True, timeout=120)
    assert result.returncode == USER_ERROR_EXIT_CODE
    assert result.stderr.count("\n") == 1 and "--guidance: must be a finite number" in result.stderr
