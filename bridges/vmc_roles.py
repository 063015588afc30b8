"""VMC roles and which bones an Assistant sends (docs/bridges.md "VMC roles").

A **Marionette** (VSeeFace's or Warudo's VMC receiver, EVMC4U) shows an avatar driven entirely by what it
receives; the Performer sends it everything (root, all bones). A **Performer** (VSeeFace, VirtualMotionCapture)
tracks the user itself and can mix in bones and blend shapes from **Assistants**. As an Assistant,
gesturecast sends no root, no availability/time messages, only the chosen bones and the viseme blend shapes.
"""

from __future__ import annotations

from dataclasses import dataclass

from gesturecast.errors import UserError
from gesturecast.models.motion.skeleton import Skeleton

MARIONETTE = "marionette"
ASSISTANT = "assistant"
DEFAULT_PORTS = {MARIONETTE: 39539, ASSISTANT: 39540}  # the VMC protocol's customary ports per receiving role
HEAD_AND_LEGS = ("Hips", "Neck", "Head", "LeftUpperLeg", "LeftLowerLeg", "LeftFoot", "LeftToes",
                 "RightUpperLeg", "RightLowerLeg", "RightFoot", "RightToes")
ARM_WORDS = ("Shoulder", "Arm", "Hand", "Thumb", "Index", "Middle", "Ring", "Little")  # shoulders to fingertips


@dataclass(frozen=True)
class BoneSelection:
    """Bone names to send, in skeleton order."""

    names: tuple[str, ...]

    @classmethod
    def parse(cls, spec: str, skeleton: Skeleton) -> BoneSelection:
        """``all``; ``upper`` (spine, chest, arms, fingers: no hips, legs, neck or head, which a Performer's
        own tracking keeps); ``arms`` (shoulders to fingertips); ``none`` (visemes only); or a comma list."""
        presets = {
            "all": skeleton.names,
            "upper": tuple(n for n in skeleton.names if n not in HEAD_AND_LEGS),
            "arms": tuple(n for n in skeleton.names if any(word in n for word in ARM_WORDS)),
            "none": (),
        }
        if spec in presets:
            return cls(presets[spec])
        wanted = [name.strip() for name in spec.split(",") if name.strip()]
        unknown = [name for name in wanted if name not in skeleton.names]
        if unknown or not wanted:
            raise UserError(f"--vmc-bones: unknown bone(s) {', '.join(unknown) or spec!r}; use all, upper, arms, "
                            f"none or a comma list of HumanBodyBones names such as {', '.join(skeleton.names[:4])}")
        return cls(tuple(name for name in skeleton.names if name in wanted))
