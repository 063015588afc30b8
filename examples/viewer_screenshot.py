"""How docs/images/viewer-avatar.png was made: real generated frames and lip sync on the viewer's avatar.

    gesturecast generate gesturecast/samples/sample_speech.wav -o sample.bvh --json sample.json
    python examples/viewer_screenshot.py sample.json \\
        --avatar AVATAR.vrm -o docs/images/viewer-avatar.png

The frames of ``sample.json`` are real (the same session as ``live``), with the viseme weights of its lip
sync (``--lipsync vrm0``, docs/lipsync.md). The picture shows the frame with the mouth at least 0.8 of its
widest opening whose elbows bend most (mid-gesture, mouth open), held still, from a little to the avatar's
left. Needs selenium and Debian's chromium.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from gesturecast.bridges.websocket_server import WebSocketBridge, WebSocketConfig
from gesturecast.frames import PoseFrame
from gesturecast.models.motion.rotations import quat_to_axis_angle
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS as SKELETON

FPS = 30
OPEN_FRACTION = 0.8  # of the widest mouth opening in the take: the frames the picture chooses from
CAMERA = {"yaw": 0.35, "pitch": 0.12, "distance": 2.3}
SETTLE_S = 1.0


def pick_frame(rotations: np.ndarray, opening: np.ndarray) -> int:
    """The open-mouthed frame (``OPEN_FRACTION`` of the widest opening) whose elbows bend most."""
    elbows = [SKELETON.index("LeftLowerArm"), SKELETON.index("RightLowerArm")]
    bend = np.linalg.norm(quat_to_axis_angle(rotations[:, elbows]), axis=-1).sum(axis=1)  # (T,) radians
    return int(np.argmax(np.where(opening >= OPEN_FRACTION * opening.max(), bend, -1.0)))


def screenshot(frame: PoseFrame, avatar: Path, output: Path) -> None:
    from selenium import webdriver

    bridge = WebSocketBridge(WebSocketConfig(port=0, avatar=avatar, lipsync=True)).start()
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    profile = tempfile.mkdtemp(prefix="gesturecast-chromium-")
    for flag in ("--headless", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                 "--window-size=1000,820", "--hide-scrollbars", f"--user-data-dir={profile}"):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=webdriver.ChromeService(executable_path="/usr/bin/chromedriver"),
                              options=options)
    try:
        driver.get(bridge.url)
        while driver.execute_script("return document.body.dataset.avatar") is None:
            time.sleep(0.1)
        driver.execute_script("Object.assign(window.gesturecastViewer.camera, arguments[0])", CAMERA)
        for seq in range(int(SETTLE_S * FPS)):
            bridge.send(dataclasses.replace(frame, seq=seq, capture_time=time.monotonic()))
            time.sleep(1 / FPS)
        output.write_bytes(driver.get_screenshot_as_png())
    finally:
        driver.quit()
        bridge.close()
        shutil.rmtree(profile, ignore_errors=True)


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("poses", type=Path, help="generate --json output of the same audio")
    parser.add_argument("--avatar", type=Path, required=True)
    parser.add_argument("-o", "--output", type=Path, required=True)
    args = parser.parse_args(argv)
    document = json.loads(args.poses.read_text())
    rotations = np.array([f["rotations"] for f in document["frames"]])  # (T, J, 4)
    visemes = np.array([f["visemes"] for f in document["frames"]])  # (T, 5) a i u e o
    k = pick_frame(rotations, visemes.sum(axis=1))
    record = document["frames"][k]
    frame = PoseFrame(k, 0.0, 0.0, np.array(record["root"]), rotations[k], style="neutral",
                      speaking=record["speaking"], visemes=visemes[k])
    screenshot(frame, args.avatar, args.output)
    print(f"frame {k} ({k / FPS:.2f} s), visemes a i u e o = {np.round(visemes[k], 2).tolist()} -> {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
