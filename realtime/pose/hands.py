"""Procedural hands: finger rotations appended to every generated body pose.

The model generates the 22 body joints of :data:`CANONICAL`; this stage turns each body pose into a pose
on :data:`CANONICAL_WITH_HANDS` (52 joints) by appending 15 finger rotations per hand:

- a natural relaxed curl: every finger flexes at its proximal, intermediate and distal joint, a little
  more from the index to the little finger; the thumb is slightly opposed (turned under the palm) and curled;
- subtle motion from the arm: the hand opens a little (less curl, fingers spread) as the wrist moves
  faster and as the arm rises, smoothed with a time constant so it never flickers;
- small independent per-finger variation: one slow sine per finger whose period and phase come from the seed.

Flexion axes come from the skeleton: a joint's bone direction ``d`` (T-pose, its child's offset) turned
toward the palm normal ``n`` (−Y: palms face down in the T-pose) is a rotation about ``d × n``, which moves
the fingertips toward the palm on both hands. Everything depends only on the stream of body poses and the
seed, so streaming and offline generation give the same fingers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gesturecast.models.motion.rotations import quat_from_axis_angle, quat_identity, quat_to_matrix
from gesturecast.models.motion.skeleton import (
    CANONICAL,
    CANONICAL_WITH_HANDS,
    FINGER_SEGMENTS,
    FINGERS,
    FINGERTIPS,
    SIDES,
    Skeleton,
    finger_joint_names,
)

PALM_NORMAL = np.array([0.0, -1.0, 0.0])  # T-pose palms face down
THUMB = "Thumb"
# body joints from the UpperChest's child to the hand, per side (FK in the UpperChest frame: the arm's own
# motion, without the root, the facing or the body's sway)
ARM_CHAIN = ("{side}Shoulder", "{side}UpperArm", "{side}LowerArm", "{side}Hand")
_CHEST_FRAME = np.broadcast_to(np.eye(3), (len(SIDES), 3, 3))  # the start of both arm chains


@dataclass(frozen=True)
class HandConfig:
    """Angles in degrees, speeds in m/s, times in seconds."""

    curl_deg: tuple[float, float, float] = (14.0, 22.0, 12.0)  # index proximal / intermediate / distal flexion
    curl_step: float = 0.15  # each finger after the index curls this fraction more (little: +45 %)
    thumb_curl_deg: tuple[float, float, float] = (6.0, 14.0, 12.0)
    thumb_opposition_deg: float = 22.0  # thumb turned under the palm about the hand's long axis
    spread_deg: float = 3.0  # fan of the fingers at rest (proximal joints, away from the middle finger)
    open_spread_deg: float = 5.0  # extra fan when the hand is fully open
    max_open: float = 0.55  # at most this fraction of the curl is released when the arm is active
    open_speed_mps: float = 1.2  # wrist speed (UpperChest frame) that counts as fully active
    speed_weight: float = 0.6  # openness = speed_weight · speed term + (1 − speed_weight) · rise term
    smoothing_s: float = 0.25  # time constant of the openness
    variation_deg: float = 3.0  # per-finger flexion wobble
    variation_period_s: float = 2.7
    period_jitter: float = 0.3  # each finger's wobble period varies by up to ±30 % with the seed


class HandPose:
    """Stateful per-stream stage: ``extend(bodies (n, 22, 4), times) -> (n, 52, 4)`` in stream order; ``reset()``
    forgets."""

    def __init__(self, fps: float, seed: int = 0, config: HandConfig | None = None,
                 skeleton: Skeleton = CANONICAL_WITH_HANDS) -> None:
        self.config = config or HandConfig()
        self.skeleton = skeleton
        self._dt = 1.0 / fps
        self._chains = np.array([[CANONICAL.index(j.format(side=side)) for j in ARM_CHAIN] for side in SIDES])  # (2, C)
        self._chain_offsets = CANONICAL.offsets[self._chains][..., None]  # (2, C, 3, 1)
        self._finger_index = np.array([[skeleton.index(n) for n in finger_joint_names(side)] for side in SIDES])
        self._flex_axes, self._spread_axes, self._opposition_axes = self._axes()  # each (2, 15, 3)
        self._rest_curl, self._rest_spread, self._open_spread = self._angles()  # each (15,) radians
        self._hang_y, self._raise_range = self._wrist_range()
        rng = np.random.default_rng(seed)
        shape = (len(SIDES), len(FINGERS))
        jitter = rng.uniform(1.0 - self.config.period_jitter, 1.0 + self.config.period_jitter, shape)  # (2, 5)
        self._frequencies = 2.0 * math.pi * jitter / self.config.variation_period_s  # (2, 5) rad/s
        self._phases = rng.uniform(0.0, 2.0 * math.pi, shape)  # (2, 5)
        self.reset()

    def reset(self) -> None:
        """Forget the previous wrist positions and the smoothed openness (a new stream starts relaxed)."""
        self._previous_wrists: np.ndarray | None = None  # (2, 3)
        self.openness = np.zeros(len(SIDES))  # (2,) 0 = relaxed curl, max_open = most open

    # ---- set-up ----
    def _bone_directions(self, side: str) -> np.ndarray:
        """(15, 3) unit direction of the bone each finger joint turns (its child's rest offset, or its tip)."""
        names = finger_joint_names(side)
        directions = []
        for k, name in enumerate(names):
            last = (k + 1) % len(FINGER_SEGMENTS) == 0
            bone = np.asarray(FINGERTIPS[name]) if last else self.skeleton.offsets[self.skeleton.index(names[k + 1])]
            directions.append(bone / np.linalg.norm(bone))
        return np.array(directions)  # (15, 3)

    def _axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Flexion axes d × n (tips toward the palm), spread axes (tips away from the middle finger) and the
        thumb's opposition axis (its forward component turned under the palm), each (2, 15, 3)."""
        flex, spread, opposition = [], [], []
        middle_z = self.skeleton.offsets[self.skeleton.index("LeftMiddleProximal"), 2]
        for side in SIDES:
            d = self._bone_directions(side)  # (15, 3)
            flex.append(_unit(np.cross(d, PALM_NORMAL)))
            knuckles = [self.skeleton.index(f"{side}{finger}Proximal") for finger in FINGERS]
            knuckles_z = np.repeat(self.skeleton.offsets[knuckles, 2], len(FINGER_SEGMENTS))  # (15,)
            lateral = np.zeros_like(d)
            lateral[:, 2] = np.sign(knuckles_z - middle_z)  # (15, 3) away from the middle finger, along ±Z
            spread.append(np.cross(d, lateral))
            opposition.append(np.broadcast_to(np.cross([0.0, 0.0, 1.0], PALM_NORMAL), d.shape))
        return np.array(flex), np.array(spread), np.array(opposition)

    def _angles(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(15,) radians: rest flexion, rest spread and extra open spread of each finger joint (same both sides)."""
        cfg = self.config
        curl, spread, open_spread = [], [], []
        for k, finger in enumerate(FINGERS):
            is_thumb = finger == THUMB
            scale = 1.0 + cfg.curl_step * max(k - 1, 0)  # index (k = 1) = 1, little = 1 + 3 · step
            curl.extend(np.radians(cfg.thumb_curl_deg if is_thumb else np.asarray(cfg.curl_deg) * scale))
            first = [0.0 if is_thumb else 1.0, 0.0, 0.0]  # spread only at the finger's proximal joint
            spread.extend(np.radians(cfg.spread_deg) * np.array(first))
            open_spread.extend(np.radians(cfg.open_spread_deg) * np.array(first))
        return np.array(curl), np.array(spread), np.array(open_spread)

    def _wrist_range(self) -> tuple[float, float]:
        """Wrist height (UpperChest frame) with the arm hanging straight down, and the arm length (the rise range)."""
        tpose_wrist_y = self._wrist_positions(quat_identity((1, CANONICAL.num_joints)))[0, 0, 1]  # arm at the shoulder
        lower_arm, hand = (CANONICAL.index(f"{SIDES[0]}{bone}") for bone in ("LowerArm", "Hand"))
        length = float(np.linalg.norm(CANONICAL.offsets[lower_arm]) + np.linalg.norm(CANONICAL.offsets[hand]))
        return tpose_wrist_y - length, length

    # ---- per latent (a few frames at a time) ----
    def _wrist_positions(self, bodies: np.ndarray) -> np.ndarray:
        """(n, 2, 3) wrist positions of both arms in the UpperChest frame from body poses (n, 22, 4).

        Rotation matrices, not quaternion products: a dozen numpy calls per batch of frames (hot path)."""
        matrices = quat_to_matrix(bodies[:, self._chains])  # (n, 2, C, 3, 3)
        rotation = np.broadcast_to(_CHEST_FRAME, matrices.shape[:2] + (3, 3))  # (n, 2, 3, 3)
        position = np.zeros(matrices.shape[:2] + (3, 1))  # (n, 2, 3, 1) column vectors
        for step in range(self._chains.shape[1]):
            position = position + rotation @ self._chain_offsets[:, step]  # (n, 2, 3, 1)
            rotation = rotation @ matrices[:, :, step]  # (n, 2, 3, 3)
        return position[..., 0]  # (n, 2, 3)

    def _update_openness(self, bodies: np.ndarray) -> np.ndarray:
        """Move the smoothed openness frame by frame toward the target set by the wrists' speed and height;
        returns each frame's openness (n, 2)."""
        cfg = self.config
        wrists = self._wrist_positions(bodies)  # (n, 2, 3)
        previous = np.concatenate([wrists[:1] if self._previous_wrists is None else self._previous_wrists[None],
                                   wrists[:-1]])  # (n, 2, 3)
        self._previous_wrists = wrists[-1]
        speed_term = np.clip(np.linalg.norm(wrists - previous, axis=-1) / self._dt / cfg.open_speed_mps, 0.0, 1.0)
        rise_term = np.clip((wrists[..., 1] - self._hang_y) / self._raise_range, 0.0, 1.0)  # (n, 2)
        targets = cfg.max_open * (cfg.speed_weight * speed_term + (1.0 - cfg.speed_weight) * rise_term)  # (n, 2)
        rate = 1.0 - math.exp(-self._dt / cfg.smoothing_s)
        openness = np.empty_like(targets)
        for k, target in enumerate(targets):
            self.openness = self.openness + rate * (target - self.openness)
            openness[k] = self.openness
        return openness

    def finger_rotations(self, openness: np.ndarray, times: np.ndarray) -> np.ndarray:
        """(n, 2, 15, 4) local XYZW finger rotations for openness (n, 2) at stream times (n,)."""
        cfg = self.config
        wobble = np.radians(cfg.variation_deg) * np.sin(self._frequencies * times[:, None, None] + self._phases)
        flex = (1.0 - openness)[..., None] * self._rest_curl + np.repeat(wobble, len(FINGER_SEGMENTS), axis=-1)
        spread = self._rest_spread + openness[..., None] / cfg.max_open * self._open_spread  # (n, 2, 15)
        axis_angles = flex[..., None] * self._flex_axes + spread[..., None] * self._spread_axes  # (n, 2, 15, 3)
        axis_angles[:, :, 0] += np.radians(cfg.thumb_opposition_deg) * self._opposition_axes[:, 0]  # thumb first
        return quat_from_axis_angle(axis_angles)  # (n, 2, 15, 4)

    def extend(self, bodies: np.ndarray, times: np.ndarray) -> np.ndarray:
        """The next frames' poses with hands: bodies (n, 22, 4) at stream times (n,) → (n, 52, 4) XYZW."""
        out = np.empty((bodies.shape[0], self.skeleton.num_joints, 4))  # (n, 52, 4)
        out[:, : CANONICAL.num_joints] = bodies
        out[:, self._finger_index] = self.finger_rotations(self._update_openness(bodies), np.asarray(times, float))
        return out

    def append(self, body: np.ndarray, t: float) -> np.ndarray:
        """One frame of :meth:`extend`: body (22, 4) at stream time ``t`` → (52, 4)."""
        return self.extend(body[None], np.array([t]))[0]


def _unit(v: np.ndarray) -> np.ndarray:
    """Rows of ``v`` (..., 3) scaled to unit length."""
    return v / np.linalg.norm(v, axis=-1, keepdims=True)
