"""The viewer's VRM avatar in headless Chromium (software WebGL): it loads, moves, faces the right way, speaks.

The avatar is the one the viewer gets with no --avatar and no $GESTURECAST_AVATAR: the packaged
cryptovoxels.vrm (bridges/viewer/avatar/), looked up from a working folder with no ../shared next to it.
"""

from __future__ import annotations

import base64
import contextlib
import dataclasses
import time
from pathlib import Path

import numpy as np
import pytest
from bridge_test_frames import moving_frame
from browser_session import SCREENSHOT_DIR, WEBGL_FLAGS, Feeder, canvas_pixels, chromium, needs_chromium, wait_for
from PIL import Image

from gesturecast.bridges.avatar_file import AVATAR_ENV_VAR, PACKAGED_AVATAR, resolve_avatar
from gesturecast.bridges.websocket_server import WebSocketBridge, WebSocketConfig
from gesturecast.frames import FACE_NAMES, VISEME_NAMES, PoseFrame
from gesturecast.models.motion.rotations import quat_from_axis_angle
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS as SKELETON

CHANGED_PIXEL_THRESHOLD = 40  # summed RGB difference that counts as a changed pixel
BRIGHT = 400  # summed RGB of the avatar's light body on the dark background (about 90)
SCREENSHOT_GAP_S = 0.6
SETTLE_S = 0.5  # a few frames of a new pose reach the page and get drawn
RAISE_RAD = 1.3  # the left arm raised from the T-pose
UPPER_PART = 0.4  # of the picture's height, from the top: above the T-posed right arm at this camera

pytestmark = needs_chromium


@pytest.fixture
def avatar(tmp_path, monkeypatch) -> Path:
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv(AVATAR_ENV_VAR, raising=False)
    found = resolve_avatar(None)
    assert found == PACKAGED_AVATAR
    return found


@pytest.fixture
def driver():
    with chromium(WEBGL_FLAGS) as browser:
        yield browser


def open_avatar_page(driver, bridge: WebSocketBridge) -> None:
    driver.get(bridge.url)
    wait_for(lambda: driver.execute_script("return document.body.dataset.avatar") == "loaded")


def look_from(driver, yaw: float) -> None:
    """Camera in front of the avatar (yaw 0: on +Z, the way it faces) or elsewhere, level with its chest."""
    camera = "Object.assign(window.gesturecastViewer.camera, {yaw: arguments[0], pitch: 0, distance: 2.6})"
    driver.execute_script(camera, yaw)


def still(frame: PoseFrame, visemes=None) -> callable:
    return lambda seq: dataclasses.replace(frame, seq=seq, visemes=visemes)


def left_arm_raised() -> PoseFrame:
    rotations = np.tile([0.0, 0.0, 0.0, 1.0], (SKELETON.num_joints, 1))
    rotations[SKELETON.index("LeftUpperArm")] = quat_from_axis_angle(np.array([0.0, 0.0, RAISE_RAD]))  # +X arm up
    return PoseFrame(0, time.monotonic(), time.monotonic(), SKELETON.offsets[0].copy(), rotations)


def mouth_pixels(image: np.ndarray) -> np.ndarray:
    """(H, W) pixels of the drawn mouth's dark red."""
    red, green, blue = image[..., 0], image[..., 1], image[..., 2]
    return (red > green + 15) & (red > blue + 10) & (red < 120)


def test_avatar_loads_and_moves(driver, avatar):
    bridge = WebSocketBridge(WebSocketConfig(port=0, avatar=avatar)).start()
    try:
        with Feeder(bridge, moving_frame):
            open_avatar_page(driver, bridge)
            wait_for(lambda: int(driver.find_element("id", "frames").text or 0) >= 10)
            first = canvas_pixels(driver, "avatar")
            shots = [first]

            def moved() -> bool:  # a loaded machine may draw no new frame within one gap: look again
                time.sleep(SCREENSHOT_GAP_S)
                shots.append(canvas_pixels(driver, "avatar"))
                return (np.abs(first - shots[-1]).sum(axis=-1) > CHANGED_PIXEL_THRESHOLD).sum() > 300

            with contextlib.suppress(AssertionError):  # the assertion below says what went wrong
                wait_for(moved)
            second = shots[-1]
            stick_hidden = driver.execute_script("return document.getElementById('stage').hidden")
    finally:
        bridge.close()
    changed = np.abs(first - second).sum(axis=-1) > CHANGED_PIXEL_THRESHOLD  # (H, W)
    assert stick_hidden, "the stick figure should give way to the avatar"
    assert (second.sum(axis=-1) > BRIGHT).sum() > 2000, "no avatar drawn"
    assert changed.sum() > 300, "the avatar did not move between screenshots"


DROP_FILE = """
const [encoded, name] = arguments;
const bytes = Uint8Array.from(atob(encoded), (c) => c.charCodeAt(0));
const transfer = new DataTransfer();
transfer.items.add(new File([bytes], name));
document.getElementById("stage-box").dispatchEvent(new DragEvent("drop", {dataTransfer: transfer, bubbles: true}));
"""


def test_without_an_avatar_the_page_asks_for_one_and_a_dropped_vrm_becomes_it(driver, avatar):
    bridge = WebSocketBridge(WebSocketConfig(port=0)).start()  # no avatar on the server
    try:
        with Feeder(bridge, moving_frame):
            driver.get(bridge.url)
            wait_for(lambda: driver.execute_script("return document.body.dataset.avatar") == "none")
            hint_before = driver.find_element("id", "drop-hint").is_displayed()
            stick_before = driver.find_element("id", "stage").is_displayed()
            driver.execute_script(DROP_FILE, base64.b64encode(avatar.read_bytes()).decode(), "mine.vrm")
            wait_for(lambda: driver.execute_script("return document.body.dataset.avatar") == "loaded")
            time.sleep(SETTLE_S)
            status = driver.find_element("id", "avatar-status").text
            hint_after = driver.find_element("id", "drop-hint").is_displayed()
            drawn = canvas_pixels(driver, "avatar")
    finally:
        bridge.close()
    assert hint_before and stick_before and not hint_after
    assert status == "mine.vrm"
    assert (drawn.sum(axis=-1) > BRIGHT).sum() > 2000, "no avatar drawn"


def test_the_left_arm_rises_on_the_left_and_the_face_looks_forward(driver, avatar):
    """From the front (yaw 0) the avatar's left hand is on the picture's right, as the stick figure has it, and
    the mouth is seen from the front only."""
    bridge = WebSocketBridge(WebSocketConfig(port=0, avatar=avatar)).start()
    try:
        with Feeder(bridge, still(left_arm_raised())):
            open_avatar_page(driver, bridge)
            look_from(driver, 0.0)
            time.sleep(SETTLE_S)
            front = canvas_pixels(driver, "avatar")
            look_from(driver, np.pi)
            time.sleep(SETTLE_S)
            back = canvas_pixels(driver, "avatar")
            look_from(driver, 0.0)
            driver.find_element("id", "show-stick").click()
            time.sleep(SETTLE_S)
            stick = canvas_pixels(driver, "stage")
    finally:
        bridge.close()
    height, width = front.shape[:2]
    SCREENSHOT_DIR.mkdir(exist_ok=True)
    Image.fromarray(np.concatenate([front, back, stick], axis=1).astype(np.uint8)).save(SCREENSHOT_DIR / "sides.png")
    top = int(UPPER_PART * height)  # above the shoulders: the head and the raised arm
    upper = front[:top].sum(axis=-1) > BRIGHT  # (top, W)
    assert upper.sum() > 200, "no raised arm"
    assert np.nonzero(upper)[1].mean() > width / 2, "the avatar's left arm should rise on the picture's right"
    left_blue = (stick[..., 2] > stick[..., 0] + 80)[:top]  # the stick figure draws left bones blue
    assert np.nonzero(left_blue)[1].mean() > width / 2
    assert mouth_pixels(front).sum() > 10 and mouth_pixels(back).sum() == 0


def test_visemes_open_the_mouth(driver, avatar):
    config = WebSocketConfig(port=0, avatar=avatar, lipsync=True, viseme_names=VISEME_NAMES["vrm1"])
    bridge = WebSocketBridge(config).start()
    pose = moving_frame(0)
    state = "return window.gesturecastViewer.avatar.mouthState()"
    try:
        with Feeder(bridge, still(pose, np.zeros(5))):
            open_avatar_page(driver, bridge)
            look_from(driver, 0.0)
            time.sleep(SETTLE_S)
            closed, closed_state = canvas_pixels(driver, "avatar"), driver.execute_script(state)
        with Feeder(bridge, still(pose, np.array([1.0, 0.0, 0.0, 0.0, 0.0]))):  # a wide-open "a"
            time.sleep(SETTLE_S)
            open_, open_state = canvas_pixels(driver, "avatar"), driver.execute_script(state)
    finally:
        bridge.close()
    assert closed_state["kind"] == "procedural"  # this avatar has no mouth blend shapes
    assert open_state["opening"] > 5 * closed_state["opening"]
    assert mouth_pixels(open_).sum() > 3 * max(1, mouth_pixels(closed).sum())


def eye_pixels(image: np.ndarray) -> np.ndarray:
    """(H, W) pixels of the drawn eyes' near-black."""
    return image.sum(axis=-1) < 90


def test_blinks_close_the_drawn_eyes_and_anger_tilts_the_brows(driver, avatar):
    config = WebSocketConfig(port=0, avatar=avatar, face_names=FACE_NAMES["vrm1"])
    bridge = WebSocketBridge(config).start()
    pose = moving_frame(0)
    state = "return window.gesturecastViewer.avatar.faceState()"
    faces = {"open": np.zeros(8), "shut": np.r_[1.0, 1.0, 1.0, np.zeros(5)], "angry": np.r_[np.zeros(4), 1.0, 0, 0, 0]}
    seen = {}
    try:
        for name, weights in faces.items():
            with Feeder(bridge, lambda seq, w=weights: dataclasses.replace(pose, seq=seq, face=w)):
                if not seen:
                    open_avatar_page(driver, bridge)
                    look_from(driver, 0.0)
                time.sleep(SETTLE_S)
                seen[name] = (canvas_pixels(driver, "avatar"), driver.execute_script(state))
    finally:
        bridge.close()
    assert seen["open"][1]["kind"] == "procedural"  # this avatar has no blink expression
    assert seen["shut"][1]["opening"] < 0.1 * seen["open"][1]["opening"]
    assert seen["angry"][1]["tilt"] < 0 == seen["open"][1]["tilt"]  # the inner ends of the brows go down
    head = slice(0, int(UPPER_PART * seen["open"][0].shape[0]))
    assert eye_pixels(seen["open"][0][head]).sum() > 2 * max(1, eye_pixels(seen["shut"][0][head]).sum())
    SCREENSHOT_DIR.mkdir(exist_ok=True)
    for name, (image, _) in seen.items():
        Image.fromarray(image.astype(np.uint8)).save(SCREENSHOT_DIR / f"face_{name}.png")


def test_on_a_port_with_a_token_the_page_fetches_the_avatar_with_the_token_of_its_url(driver, avatar):
    token = "correct-horse-battery-staple"
    bridge = WebSocketBridge(WebSocketConfig(port=0, avatar=avatar, token=token)).start()
    try:
        with Feeder(bridge, moving_frame):
            driver.get(bridge.url)  # no token in the URL: the server refuses the avatar (401)
            wait_for(lambda: driver.execute_script("return document.body.dataset.avatar") == "none")
            without = driver.execute_script("return document.body.dataset.avatar")
            driver.get(f"{bridge.url}?token={token}")
            wait_for(lambda: driver.execute_script("return document.body.dataset.avatar") == "loaded")
            with_token = driver.execute_script("return document.body.dataset.avatar")
    finally:
        bridge.close()
    assert (without, with_token) == ("none", "loaded")
