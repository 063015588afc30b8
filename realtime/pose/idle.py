"""Procedural idle motion for silence: breathing and small sways on the canonical skeleton.

When nobody speaks the avatar should neither freeze nor gesture. Each idle channel is a small rotation
(a few degrees) of one joint about one body axis, driven by a sine oscillator whose phase and exact
period are drawn from a seed, so the motion is smooth, never repeats exactly, and is deterministic.

Offsets are applied in the parent's frame on top of a base pose (default: arms relaxed at the sides):
local = offset ⊗ base. The upper legs counter-rotate the hips' sway so the feet stay planted.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gesturecast.models.motion.rotations import quat_conj, quat_from_axis_angle, quat_mul
from gesturecast.models.motion.skeleton import CANONICAL

X, Y, Z = 0, 1, 2
PERIOD_JITTER = 0.1  # each oscillator's period varies by up to ±10 % with the seed
GOLDEN_RATIO = 1.618034  # slow companions of the sway / head / arm oscillators, never in phase with them
RIGHT_ARM_PERIOD_FACTOR = 1.13  # the right arm's periods against the left's: the arms never move as one
LEG_JOINTS = ("LeftUpperLeg", "RightUpperLeg")


@dataclass(frozen=True)
class IdleConfig:
    """Amplitudes in degrees, periods in seconds; arm_down_deg / elbow_bend_deg shape the default base pose."""

    breath_period_s: float = 4.2
    breath_deg: float = 0.8
    sway_period_s: float = 7.5
    sway_deg: float = 1.2
    head_period_s: float = 5.5
    head_deg: float = 2.0
    arms_period_s: float = 3.1
    arms_deg: float = 5.0
    arm_down_deg: float = 80.0
    elbow_bend_deg: float = 12.0

    def oscillator_periods(self) -> dict[str, float]:
        return {
            "breath": self.breath_period_s,
            "sway": self.sway_period_s,
            "sway_slow": self.sway_period_s * GOLDEN_RATIO,
            "head": self.head_period_s,
            "head_slow": self.head_period_s * GOLDEN_RATIO,
            "arm_left": self.arms_period_s,
            "arm_right": self.arms_period_s * RIGHT_ARM_PERIOD_FACTOR,
            "elbow_left": self.arms_period_s * GOLDEN_RATIO,
            "elbow_right": self.arms_period_s * GOLDEN_RATIO * RIGHT_ARM_PERIOD_FACTOR,
        }

    def amplitudes(self) -> dict[str, float]:
        return {"breath": self.breath_deg, "sway": self.sway_deg, "head": self.head_deg, "arms": self.arms_deg}


# joint, axis, amplitude group, scale of that amplitude, oscillator
_CHANNELS: tuple[tuple[str, int, str, float, str], ...] = (
    ("Spine", X, "breath", 0.6, "breath"),
    ("Chest", X, "breath", 0.8, "breath"),
    ("UpperChest", X, "breath", 1.0, "breath"),
    ("Neck", X, "breath", -1.6, "breath"),  # keeps the gaze level while the chest rocks
    ("LeftShoulder", Z, "breath", 0.6, "breath"),  # shoulders lift on the in-breath
    ("RightShoulder", Z, "breath", -0.6, "breath"),
    ("Hips", Z, "sway", 1.0, "sway"),  # weight shift from leg to leg
    ("Hips", Y, "sway", 0.6, "sway_slow"),
    ("Spine", Z, "sway", -0.6, "sway"),  # the upper body partly rebalances the hip roll
    ("LeftUpperArm", X, "sway", 0.8, "sway_slow"),
    ("RightUpperArm", X, "sway", 0.8, "sway_slow"),
    ("Neck", Y, "head", 0.4, "head"),
    ("Head", Y, "head", 1.0, "head"),
    ("Head", X, "head", 0.5, "head_slow"),
    ("LeftUpperArm", X, "arms", 0.5, "arm_left"),  # the hands drift: each arm swings and bends on its own
    ("RightUpperArm", X, "arms", 0.5, "arm_right"),
    ("LeftLowerArm", Y, "arms", 1.0, "elbow_left"),
    ("RightLowerArm", Y, "arms", 1.0, "elbow_right"),
)


def relaxed_pose(config: IdleConfig) -> np.ndarray:
    """Canonical base pose (J, 4): T-pose with the arms lowered to the sides and the elbows slightly bent."""
    axis_angles = np.zeros((CANONICAL.num_joints, 3))  # (J, 3)
    down, bend = np.radians(config.arm_down_deg), np.radians(config.elbow_bend_deg)
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        axis_angles[CANONICAL.index(f"{side}UpperArm"), Z] = -sign * down  # the arm points ±X at rest
        axis_angles[CANONICAL.index(f"{side}LowerArm"), Y] = -sign * bend  # forearm forward (+Z)
    return quat_from_axis_angle(axis_angles)


class IdleMotion:
    """Idle pose as a function of stream time: ``rotations(t)`` (..., J, 4) XYZW, ``root_position(t)`` (..., 3)."""

    def __init__(
        self,
        config: IdleConfig | None = None,
        seed: int = 0,
        base_rotations: np.ndarray | None = None,
        base_root: np.ndarray | None = None,
    ) -> None:
        self.config = config or IdleConfig()
        self.base_rotations = relaxed_pose(self.config) if base_rotations is None else np.asarray(base_rotations)
        self.base_root = CANONICAL.offsets[0].copy() if base_root is None else np.asarray(base_root, dtype=float)
        rng = np.random.default_rng(seed)
        periods = self.config.oscillator_periods()
        self._names = list(periods)
        jitter = rng.uniform(1.0 - PERIOD_JITTER, 1.0 + PERIOD_JITTER, len(periods))
        self._frequencies = 2.0 * np.pi * jitter / np.array(list(periods.values()))  # (O,) rad/s
        self._phases = rng.uniform(0.0, 2.0 * np.pi, len(periods))  # (O,)
        self._mixing = self._channel_matrix()  # (J * 3, O) radians per unit oscillator

    def _channel_matrix(self) -> np.ndarray:
        amplitudes = self.config.amplitudes()
        mixing = np.zeros((CANONICAL.num_joints * 3, len(self._names)))
        for joint, axis, group, scale, oscillator in _CHANNELS:
            row = CANONICAL.index(joint) * 3 + axis
            mixing[row, self._names.index(oscillator)] += np.radians(amplitudes[group] * scale)
        return mixing

    def offsets(self, t: np.ndarray | float) -> np.ndarray:
        """Idle offset rotations (..., J, 4) before the base pose and the leg counter-rotation."""
        t = np.asarray(t, dtype=np.float64)
        waves = np.sin(t[..., None] * self._frequencies + self._phases)  # (..., O)
        axis_angles = waves @ self._mixing.T  # (..., J * 3)
        return quat_from_axis_angle(axis_angles.reshape(*t.shape, CANONICAL.num_joints, 3))  # (..., J, 4)

    def rotations(self, t: np.ndarray | float) -> np.ndarray:
        """Local XYZW rotations (..., J, 4) at stream time ``t`` (seconds, scalar or array)."""
        offsets = self.offsets(t)  # (..., J, 4)
        rotations = quat_mul(offsets, np.broadcast_to(self.base_rotations, offsets.shape))  # (..., J, 4)
        hips = CANONICAL.index("Hips")
        base_hips = self.base_rotations[hips]  # (4,)
        leg_counter = quat_mul(quat_conj(base_hips), quat_mul(quat_conj(offsets[..., hips, :]), base_hips))  # (..., 4)
        for leg in LEG_JOINTS:
            j = CANONICAL.index(leg)
            rotations[..., j, :] = quat_mul(leg_counter, self.base_rotations[j])
        return rotations

    def root_position(self, t: np.ndarray | float) -> np.ndarray:
        """Hips position (..., 3) in metres: the base root (the feet stay planted)."""
        shape = np.shape(t)
        return np.broadcast_to(self.base_root, (*shape, 3)).copy()
