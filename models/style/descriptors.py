"""Style read from joint positions (forward kinematics), not from the network that made the motion.

Positions are taken in the body's own frame: the Hips' ground position removed and the facing yaw turned to +Z,
lengths divided by the canonical body height H. Per frame (:func:`frame_descriptors`) or per clip / window
(:func:`clip_descriptor`, :func:`window_features`):

- ``wrist_speed`` (H/s) and ``tempo`` (1/s: wrist speed over the wrists' RMS excursion about their mean, about how
  many times a second the hands turn back); ``wrist_height`` (H above the hips), ``hand_spread`` (H between the
  hands), ``hand_forward`` (H in front of the hips);
- ``forward_lean`` (rad: the hips→neck line's tilt toward the facing), ``head_pitch`` (rad: the head's forward axis
  below the horizon), ``shoulder_height`` (H: the upper arms above the neck's base), ``stance`` (H between the feet).

:func:`style_distance` is the Euclidean distance of two clips' descriptors (:data:`FK_MEASURE`: the
issue-independent measure of ``bench styles``); the judge's window features (:data:`JUDGE_FEATURES`) use only what
speech gestures share with any action: the upper body, posture and tempo (no stance).
"""

from __future__ import annotations

import numpy as np

from gesturecast.models.motion.motion_features import facing_yaw
from gesturecast.models.motion.rotations import quat_from_yaw, quat_mul, quat_rotate
from gesturecast.models.motion.skeleton import CANONICAL

BODY_HEIGHT = CANONICAL.height()
_J = {name: CANONICAL.index(name) for name in CANONICAL.names}
HANDS = [_J["LeftHand"], _J["RightHand"]]
FK_MEASURE = ("wrist_speed", "wrist_height", "hand_spread", "forward_lean", "stance", "tempo", "head_pitch")
JUDGE_FEATURES = ("wrist_speed", "wrist_speed_sd", "tempo", "wrist_height", "wrist_height_sd", "hand_spread",
                  "hand_forward", "forward_lean", "head_pitch", "head_pitch_sd", "shoulder_height", "head_speed",
                  "elbow_height", "elbow_bend", "head_height", "vertical_share", "sharpness")
MIN_FRAMES = 8


def body_frame_positions(rotations: np.ndarray, root: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Joint positions (T, J, 3) in the body's frame in units of H, and global rotations in that frame (T, J, 4),
    from canonical local rotations (T, J', 4) (J' ≥ J: finger joints are ignored) and hips positions (T, 3)."""
    local = rotations[:, :CANONICAL.num_joints]  # (T, J, 4)
    unturn = quat_from_yaw(-facing_yaw(local[:, 0]))  # (T, 4)
    hips = local[:, 0].copy()
    local = local.copy()
    local[:, 0] = quat_mul(unturn, hips)
    ground = np.stack([np.zeros(len(root)), root[:, 1], np.zeros(len(root))], axis=-1)  # (T, 3) height kept
    global_rot, positions = CANONICAL.forward_kinematics(local, ground)
    return positions / BODY_HEIGHT, global_rot


def frame_descriptors(rotations: np.ndarray, root: np.ndarray) -> dict[str, np.ndarray]:
    """Per-frame quantities (T,) of a clip (module docstring); the speed-based ones need the clip's fps later."""
    positions, global_rot = body_frame_positions(rotations, root)  # (T, J, 3), (T, J, 4)
    hips = positions[:, _J["Hips"]]  # (T, 3)
    hands = positions[:, HANDS]  # (T, 2, 3)
    neck = positions[:, _J["Neck"]]
    lean = neck - hips  # (T, 3)
    forward = quat_rotate(global_rot[:, _J["Head"]], np.broadcast_to([0.0, 0.0, 1.0], (len(positions), 3)))
    elbows = positions[:, [_J["LeftLowerArm"], _J["RightLowerArm"]]]  # (T, 2, 3)
    shoulders = positions[:, [_J["LeftUpperArm"], _J["RightUpperArm"]]]
    feet = positions[:, [_J["LeftFoot"], _J["RightFoot"]]]
    return {
        "hands": hands - hips[:, None],  # (T, 2, 3)
        "head": positions[:, _J["Head"]] - hips,  # (T, 3)
        "wrist_height": (hands[..., 1] - hips[:, None, 1]).mean(axis=1),
        "hand_spread": np.linalg.norm(hands[:, 0] - hands[:, 1], axis=-1),
        "hand_forward": (hands[..., 2] - hips[:, None, 2]).mean(axis=1),
        "forward_lean": np.arctan2(lean[:, 2], lean[:, 1]),
        "head_pitch": np.arcsin(np.clip(-forward[:, 1], -1.0, 1.0)),
        "shoulder_height": (shoulders[..., 1] - neck[:, None, 1]).mean(axis=1),
        "elbow_height": (elbows[..., 1] - hips[:, None, 1]).mean(axis=1),
        "stance": np.linalg.norm(feet[:, 0] - feet[:, 1], axis=-1),
        "elbow_bend": _angle(elbows - shoulders, hands - elbows).mean(axis=1),
        "head_height": positions[:, _J["Head"], 1] - hips[:, 1],
    }


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle (rad) between vectors (..., 3)."""
    cos = np.sum(a * b, axis=-1) / np.maximum(np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1), 1e-9)
    return np.arccos(np.clip(cos, -1.0, 1.0))


def _speed(points: np.ndarray, fps: float) -> np.ndarray:
    """Mean speed (T-1,) of points (T, ..., 3) over their non-time axes but the last."""
    speed = np.linalg.norm(np.diff(points, axis=0), axis=-1) * fps  # (T-1, ...)
    return speed.reshape(len(speed), -1).mean(axis=1)


def _summary(frames: dict[str, np.ndarray], fps: float) -> dict[str, float]:
    """Descriptors of a run of frames (a clip or a window) from its per-frame quantities."""
    hands = frames["hands"]  # (T, 2, 3)
    wrist_speed = _speed(hands, fps)  # (T-1,)
    velocity = np.diff(hands, axis=0) * fps  # (T-1, 2, 3)
    acceleration = np.linalg.norm(np.diff(velocity, axis=0), axis=-1).mean() * fps
    excursion = float(np.sqrt(np.mean(np.sum((hands - hands.mean(axis=0)) ** 2, axis=-1))))
    out = {name: float(np.mean(frames[name])) for name in ("wrist_height", "hand_spread", "hand_forward",
                                                             "forward_lean", "head_pitch", "shoulder_height",
                                                             "elbow_height", "stance", "elbow_bend",
                                                             "head_height")}
    out.update(wrist_speed=float(wrist_speed.mean()), wrist_speed_sd=float(wrist_speed.std()),
               tempo=float(wrist_speed.mean()) / max(excursion, 1e-3),
               wrist_height_sd=float(frames["wrist_height"].std()), head_pitch_sd=float(frames["head_pitch"].std()),
               head_speed=float(_speed(frames["head"], fps).mean()),
               vertical_share=float(np.abs(velocity[..., 1]).mean()
                                    / max(np.linalg.norm(velocity, axis=-1).mean(), 1e-6)),
               sharpness=float(acceleration / max(wrist_speed.mean(), 1e-3)))
    return out


def clip_descriptor(rotations: np.ndarray, root: np.ndarray, fps: float, names: tuple[str, ...] = FK_MEASURE
                    ) -> np.ndarray:
    """(len(names),) descriptors of a whole clip (rotations (T, J, 4), hips (T, 3))."""
    if len(rotations) < MIN_FRAMES:
        raise ValueError(f"a style descriptor needs at least {MIN_FRAMES} frames, got {len(rotations)}")
    summary = _summary(frame_descriptors(rotations, root), fps)
    return np.array([summary[name] for name in names])


def window_features(rotations: np.ndarray, root: np.ndarray, fps: float, window: int = 64, stride: int = 16
                    ) -> np.ndarray:
    """(W, len(JUDGE_FEATURES)) judge features of every window of a clip (one window when it is shorter)."""
    frames = frame_descriptors(rotations, root)
    length = len(rotations)
    starts = range(0, max(length - window, 0) + 1, stride)
    rows = []
    for start in starts:
        part = {name: value[start:start + window] for name, value in frames.items()}
        summary = _summary(part, fps)
        rows.append([summary[name] for name in JUDGE_FEATURES])
    return np.array(rows)


def style_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Euclidean distance of two clip descriptors (:data:`FK_MEASURE` order)."""
    return float(np.linalg.norm(np.asarray(a) - np.asarray(b)))
