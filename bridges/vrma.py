"""VRM Animation files (``.vrma``): the pose stream as a glTF binary with the ``VRMC_vrm_animation`` extension.

What the file holds (VRMC_vrm_animation 1.0 spec, github.com/vrm-c/vrm-specification):

- one glTF node per bone of the skeleton (52: body and fingers), named and mapped to its VRM 1.0 humanoid
  bone in ``extensions.VRMC_vrm_animation.humanoid.humanBones``; the rest pose is the skeleton's T-pose
  (translation = rest offset, identity rotation), so a loader's rest correction
  ``parentWorldRest · q · worldRestᵀ`` leaves the stream's local rotations as they are;
- one animation, 30 fps (the stream's rate): a rotation channel per bone and the Hips translation
  (metres, internal frame: right-handed, Y-up, facing +Z, as VRM 1.0);
- by default (``bones="folded"``, ``generate --vrma-bones folded``) the UpperChest rotation is folded into the
  Chest (:func:`fold_upper_chest`), because stock players skip the tracks of bones an avatar lacks and many
  avatars have no upper chest; ``"full"`` writes every bone as generated;
- with viseme weights (``PoseFrame.visemes``), the expression presets ``aa ih ou ee oh``, and with face weights
  (``PoseFrame.face``) ``blink blinkLeft blinkRight happy angry sad relaxed surprised``, as nodes whose
  translation x carries the weight (the spec's expression encoding), one translation channel each.

Frames are kept in memory until :meth:`VrmaWriter.save` (52 bones · 16 bytes · 30 fps ≈ 25 kB per second);
the file replaces its target in one step (:func:`gesturecast.files.atomic_file`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gesturecast.bridges.gltf_binary import FloatBuffer, glb_bytes
from gesturecast.errors import UserError
from gesturecast.files import atomic_file, check_output_target
from gesturecast.frames import FACE_NAMES, VISEME_NAMES, PoseFrame
from gesturecast.models.motion.rotations import quat_mul
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS, Skeleton

EXTENSION = "VRMC_vrm_animation"
SPEC_VERSION = "1.0"
VRMA_FPS = 30.0
VISEME_PRESETS = VISEME_NAMES["vrm1"]  # weight order a i u e o
FACE_PRESETS = FACE_NAMES["vrm1"]  # PoseFrame.face order
VRM1_THUMB_NAMES = {"ThumbProximal": "ThumbMetacarpal", "ThumbIntermediate": "ThumbProximal"}  # VRM 1.0 renames
FOLDED = "folded"  # UpperChest folded into Chest: what a player shows on an avatar without an upper chest
FULL = "full"  # every bone as generated
VRMA_BONES = (FOLDED, FULL)
IDENTITY = (0.0, 0.0, 0.0, 1.0)


def vrm_bone_name(unity_name: str) -> str:
    """Unity HumanBodyBones name -> VRM 1.0 humanoid bone name (lower camel case; the thumb is renamed:
    Unity's proximal / intermediate thumb bones are VRM 1.0's metacarpal / proximal)."""
    for unity, vrm in VRM1_THUMB_NAMES.items():
        if unity_name.endswith(unity):
            unity_name = unity_name[: -len(unity)] + vrm
    return unity_name[0].lower() + unity_name[1:]


def bone_nodes(skeleton: Skeleton) -> list[dict]:
    """One node per joint (index = joint index): name, rest translation, children."""
    nodes = [{"name": vrm_bone_name(name), "translation": skeleton.offsets[j].tolist()}
             for j, name in enumerate(skeleton.names)]
    for child, parent in enumerate(skeleton.parents):
        if parent >= 0:
            nodes[parent].setdefault("children", []).append(child)
    return nodes


def fold_upper_chest(rotations: np.ndarray, skeleton: Skeleton) -> np.ndarray:
    """(T, J, 4) local rotations with UpperChest's composed into Chest's (Chest' = Chest·UpperChest) and UpperChest
    set to identity; unchanged for a skeleton without both bones.

    The world rotation of every bone from the upper chest up (neck, head, shoulders, arms, hands, fingers) stays
    as generated, as in the project's viewer. Without the fold, a stock player (three-vrm-animation) on an avatar
    that has no upper chest drops its rotation (8.6° median on the bundled sample), turning the whole upper body
    with it: the hands move 44 mm (median; up to 91). The price, on an avatar that has an upper chest: the upper
    body pivots at the chest, 0.23 m lower, which moves the hands by about 35 mm (``--vrma-bones full`` is exact
    there).
    """
    if not {"Chest", "UpperChest"} <= set(skeleton.names):
        return rotations
    chest, upper = skeleton.index("Chest"), skeleton.index("UpperChest")
    if skeleton.parents[upper] != chest:
        raise ValueError("folding UpperChest needs it to be a child of Chest")
    folded = np.array(rotations, copy=True)  # (T, J, 4)
    folded[:, chest] = quat_mul(rotations[:, chest], rotations[:, upper])
    folded[:, upper] = IDENTITY
    return folded


def check_vrma_bones(bones: str) -> str:
    """``bones`` when it is one of :data:`VRMA_BONES`; a one-line error otherwise."""
    if bones not in VRMA_BONES:
        raise UserError(f"--vrma-bones {bones!r}: use one of {', '.join(VRMA_BONES)}")
    return bones


def vrma_bytes(rotations: np.ndarray, root_positions: np.ndarray, expressions: dict[str, np.ndarray] | None = None,
               skeleton: Skeleton = CANONICAL_WITH_HANDS, fps: float = VRMA_FPS, bones: str = FOLDED) -> bytes:
    """The .vrma file: rotations (T, J, 4) XYZW local, root_positions (T, 3) metres, expressions {VRM 1.0 preset
    name: (T,) weights} (none: no expression tracks); ``bones``: ``"folded"`` (UpperChest into Chest,
    :func:`fold_upper_chest`) or ``"full"``."""
    if check_vrma_bones(bones) == FOLDED:
        rotations = fold_upper_chest(rotations, skeleton)
    buffer = FloatBuffer()
    times = buffer.add(np.arange(len(rotations)) / fps, with_bounds=True)  # (T,) seconds
    nodes = bone_nodes(skeleton)
    channels = [(j, "rotation", buffer.add(rotations[:, j])) for j in range(skeleton.num_joints)]  # (T, 4) each
    channels.append((0, "translation", buffer.add(root_positions)))  # (T, 3) Hips
    extension = {"specVersion": SPEC_VERSION,
                 "humanoid": {"humanBones": {node["name"]: {"node": j} for j, node in enumerate(nodes)}}}
    if expressions:
        presets = {}
        for name, weights in expressions.items():
            presets[name] = {"node": len(nodes)}
            weight_as_x = np.zeros((len(weights), 3))  # (T, 3): translation x = weight
            weight_as_x[:, 0] = weights
            channels.append((len(nodes), "translation", buffer.add(weight_as_x)))
            nodes.append({"name": f"expression_{name}"})
        extension["expressions"] = {"preset": presets}
    animation = {
        "name": "gesturecast",
        "samplers": [{"input": times, "output": output, "interpolation": "LINEAR"} for _, _, output in channels],
        "channels": [{"sampler": i, "target": {"node": node, "path": path}}
                     for i, (node, path, _) in enumerate(channels)],
    }
    document = {
        "asset": {"version": "2.0", "generator": "gesturecast"},
        "extensionsUsed": [EXTENSION],
        "extensions": {EXTENSION: extension},
        "scene": 0,
        "scenes": [{"nodes": [0, *range(skeleton.num_joints, len(nodes))]}],
        "nodes": nodes,
        "animations": [animation],
    }
    return glb_bytes(document, buffer)


class VrmaWriter:
    """Append PoseFrame batches with :meth:`write`; :meth:`save` writes the .vrma (``generate --vrma``), with
    UpperChest folded into Chest unless ``bones="full"``."""

    def __init__(self, path: str | Path, skeleton: Skeleton = CANONICAL_WITH_HANDS, bones: str = FOLDED) -> None:
        self.path = Path(path)
        check_output_target(self.path)  # a folder or FIFO target is refused before any work
        self.skeleton = skeleton
        self.bones = check_vrma_bones(bones)
        self.num_frames = 0
        self._rotations: list[np.ndarray] = []
        self._roots: list[np.ndarray] = []
        self._weights: dict[tuple[str, ...], list[np.ndarray]] = {VISEME_PRESETS: [], FACE_PRESETS: []}
        self._carried: set[tuple[str, ...]] = set()  # the weight kinds some frame carried

    def write(self, frames: list[PoseFrame]) -> None:
        """Add frames (in stream order); frames without viseme or face weights count as a closed mouth and a
        neutral, open-eyed face."""
        for frame in frames:
            self._rotations.append(frame.rotations)
            self._roots.append(frame.root_position)
            for names, weights in ((VISEME_PRESETS, frame.visemes), (FACE_PRESETS, frame.face)):
                self._weights[names].append(np.zeros(len(names)) if weights is None else weights)
                if weights is not None:
                    self._carried.add(names)
        self.num_frames += len(frames)

    def _expressions(self) -> dict[str, np.ndarray]:
        """{preset name: (T,) weights} of the weight kinds some frame carried."""
        tracks = {}
        for names in [names for names in self._weights if names in self._carried]:  # visemes, then the face
            weights = np.stack(self._weights[names])  # (T, n)
            tracks.update({name: weights[:, k] for k, name in enumerate(names)})
        return tracks

    def save(self) -> None:
        """Write the file (replacing ``path`` in one step)."""
        if not self.num_frames:
            raise UserError(f"cannot write {self.path}: no frames")
        data = vrma_bytes(np.stack(self._rotations), np.stack(self._roots),  # (T, J, 4), (T, 3)
                          self._expressions(), self.skeleton, bones=self.bones)
        with atomic_file(self.path, binary=True) as handle:
            handle.write(data)

    def __enter__(self) -> VrmaWriter:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._rotations, self._roots = [], []
        self._weights = {names: [] for names in self._weights}
