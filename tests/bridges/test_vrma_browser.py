"""A .vrma from `gesturecast generate` played with @pixiv/three-vrm-animation on the default avatar in headless
Chromium: the avatar's bone rotations at a few instants equal the BVH of the same run, its chest carrying the
BVH's Chest · UpperChest (the avatar has no upper chest; the file folds it in by default)."""

from __future__ import annotations

import base64
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import soundfile
from browser_session import WEBGL_FLAGS, chromium, needs_chromium, wait_for

from gesturecast.bridges.avatar_file import PACKAGED_AVATAR
from gesturecast.bridges.vrma import vrm_bone_name
from gesturecast.bridges.websocket_server import WebSocketBridge, WebSocketConfig
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.motion.retarget import load_motion_file
from gesturecast.models.motion.rotations import quat_mul

SAMPLE = Path(__file__).resolve().parents[2] / "gesturecast" / "samples" / "sample_speech.wav"
SPEECH_SECONDS = 4
SAMPLE_FRAMES = (15, 45, 75, 105)  # instants compared (30 fps frames)
BONES = ("Hips", "Spine", "Chest", "Neck", "Head", "LeftUpperArm", "LeftLowerArm", "RightUpperArm", "RightLowerArm",
         "LeftHand", "RightIndexProximal")
TOLERANCE_DEG = 0.2  # float32 in the .vrma, 6 decimals of Euler degrees in the BVH
VRM0_MIRROR = np.array([-1.0, 1.0, -1.0, 1.0])  # VRM 0.x normalized bones face -Z: (x, y, z, w) -> (-x, y, -z, w)

pytestmark = needs_chromium

PLAY_AND_SAMPLE = """
const [encoded, times, bones, done] = arguments;
const buffer = Uint8Array.from(atob(encoded), (c) => c.charCodeAt(0)).buffer;
const avatar = window.gesturecastViewer.avatar;
avatar.playAnimation(buffer).then(() => done(times.map((t) => avatar.sampleAnimation(t, bones))),
                                  (error) => done(String(error)));
"""


@pytest.fixture(scope="module")
def generated(tmp_path_factory) -> tuple[Path, Path]:
    """(BVH, .vrma) written by one `gesturecast generate` run on the first seconds of the bundled sample."""
    folder = tmp_path_factory.mktemp("vrma")
    speech = folder / "speech.wav"
    soundfile.write(speech, load_audio(SAMPLE)[: SPEECH_SECONDS * SAMPLE_RATE], SAMPLE_RATE, subtype="PCM_16")
    command = "import sys; from gesturecast.cli import main; sys.exit(main(sys.argv[1:]))"
    result = subprocess.run([sys.executable, "-c", command, "generate", str(speech), "-o", str(folder / "take.bvh"),
                             "--vrma", str(folder / "take.vrma")], capture_output=True, text=True, timeout=300,
                            env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"})
    assert result.returncode == 0, result.stderr[-2000:]
    return folder / "take.bvh", folder / "take.vrma"


def angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(...) angles between unit quaternions (..., 4), sign-blind."""
    return np.degrees(2 * np.arccos(np.clip(np.abs((a * b).sum(axis=-1)), 0.0, 1.0)))


def test_vrma_on_the_avatar_matches_the_bvh_of_the_same_run(generated, tmp_path):
    bvh, vrma = generated
    avatar = tmp_path / "avatar.vrm"
    shutil.copyfile(PACKAGED_AVATAR, avatar)
    bridge = WebSocketBridge(WebSocketConfig(port=0, avatar=avatar)).start()
    times = [frame / 30.0 for frame in SAMPLE_FRAMES]
    names = [vrm_bone_name(bone) for bone in BONES]
    try:
        with chromium(WEBGL_FLAGS) as driver:
            driver.get(bridge.url)
            wait_for(lambda: driver.execute_script("return document.body.dataset.avatar") == "loaded")
            sampled = driver.execute_async_script(PLAY_AND_SAMPLE, base64.b64encode(vrma.read_bytes()).decode(),
                                                  times, names)
    finally:
        bridge.close()
    assert not isinstance(sampled, str), sampled
    motion = load_motion_file(bvh, keep_hands=True)
    expected = motion.rotations[np.ix_(SAMPLE_FRAMES, [motion.skeleton.index(b) for b in BONES])]  # (S, B, 4)
    upper_chest = motion.rotations[SAMPLE_FRAMES, motion.skeleton.index("UpperChest")]  # (S, 4)
    assert angle_deg(upper_chest, np.array([0.0, 0.0, 0.0, 1.0])).min() > 3.0, "no upper chest to fold"
    chest = BONES.index("Chest")
    expected[:, chest] = quat_mul(expected[:, chest], upper_chest)  # a stock player drops an unfolded UpperChest
    errors = angle_deg(np.asarray(sampled) * VRM0_MIRROR, expected)  # (S, B)
    assert angle_deg(expected, np.array([0.0, 0.0, 0.0, 1.0])).max() > 5.0, "a motionless take tests nothing"
    assert errors.max() < TOLERANCE_DEG, dict(zip(BONES, errors.max(axis=0).round(3), strict=True))
