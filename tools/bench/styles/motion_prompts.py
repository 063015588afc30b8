"""Motion prompts from a skeleton the model never saw: real styled takes written as 120 fps CMU-style BVH.

For each of two styles (default "old" and "angry") one take of the dataset cache is chosen — a motion-only
take before a paired one, a held-out (val/test) segment before a train one, an in-place gesture (waving,
guiding, calling, ...) before locomotion — and written with :mod:`.cmu_bvh`. Both clips then drive
generation on the same speech as ``StylePrompt("motion", path)``: the product reads them through its CMU
joint map, resamples 120 → 30 fps and embeds them with the motion-prompt encoder. The result is the
difference of the two outputs' mean upper-body poses (:func:`.measures.mean_pose_difference_deg`), beside
the same difference for the two styles' label prompts.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.dataset.cache import is_full_body, load_take, read_index
from gesturecast.models.evaluation.style_classifier import StyleClassifier
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.tools.bench.styles.cmu_bvh import CMU_FPS, write_cmu_bvh
from gesturecast.tools.bench.styles.guidance_sweep import accuracy_from_counts, confusion_row
from gesturecast.tools.bench.styles.measures import mean_pose_difference_deg
from gesturecast.tools.bench.styles.runs import StudyRuns, StyleRequest, label
from gesturecast.tools.eval.generate import Generated

HELD_OUT_SPLITS = ("test", "val")
GESTURE_CONTENTS = ("wave", "raise-up", "bye", "guide", "respond", "call")  # Bandai contents done in place


@dataclass(frozen=True)
class PromptClip:
    style: str
    take: str
    split: str
    path: Path
    seconds: float


def _segment(record: dict) -> dict:
    held_out = [s for s in record["segments"] if s["split"] in HELD_OUT_SPLITS]
    return (held_out or record["segments"])[0]


def _preference(record: dict) -> tuple:
    """Sort key: motion-only, held-out, an in-place gesture, then by name."""
    gesture = any(f"_{content}" in record["name"] for content in GESTURE_CONTENTS)
    return record["has_audio"], _segment(record)["split"] not in HELD_OUT_SPLITS, not gesture, record["name"]


def pick_take(cache: Path, style: str) -> dict:
    """The cache index record of the preferred take labelled ``style``; UserError when there is none."""
    takes = [record for record in read_index(cache)["takes"] if record["style"] == style and is_full_body(record)]
    if not takes:
        raise UserError(f"the dataset cache {cache} has no take labelled {style!r} for a motion prompt")
    return min(takes, key=_preference)


def write_prompt_clip(cache: Path, style: str, folder: Path, fps: float = CMU_FPS) -> PromptClip:
    record = pick_take(cache, style)
    segment = _segment(record)
    motion, _ = load_take(cache, record)
    motion = motion.slice(segment["start"], segment["stop"])
    path = write_cmu_bvh(motion, folder / f"{style}_cmu_{fps:g}fps.bvh", fps)
    return PromptClip(style, record["name"], segment["split"], path, motion.duration)


def _style_accuracy(classifier: StyleClassifier, style: str, generated: list[Generated]) -> float | None:
    if style not in classifier.labels:
        return None
    return accuracy_from_counts(sum(confusion_row(classifier, g.positions) for g in generated),
                                classifier.labels.index(style))


def prompt_comparison(runs: StudyRuns, classifier: StyleClassifier, prompts: tuple[PromptClip, PromptClip],
                      guidance: float, seeds: tuple[int, ...]) -> dict:
    """Mean upper-body pose difference (degrees) of the two motion prompts' results and of the two labels', per
    seed and averaged; the classifier's accuracy on the motion prompts' results (windows of all seeds)."""
    by_motion = [[runs.generate(StyleRequest(StylePrompt("motion", str(p.path)), guidance, seed=seed))
                  for seed in seeds] for p in prompts]
    by_label = [[runs.generate(label(p.style, guidance, seed)) for seed in seeds] for p in prompts]
    motion_deg = [mean_pose_difference_deg(a.rotations, b.rotations) for a, b in zip(*by_motion, strict=True)]
    label_deg = [mean_pose_difference_deg(a.rotations, b.rotations) for a, b in zip(*by_label, strict=True)]
    return {"motion_prompts_deg": float(np.mean(motion_deg)), "label_prompts_deg": float(np.mean(label_deg)),
            "per_seed": {"motion_prompts_deg": motion_deg, "label_prompts_deg": label_deg},
            "motion_prompt_style_accuracy": {p.style: _style_accuracy(classifier, p.style, g)
                                             for p, g in zip(prompts, by_motion, strict=True)}}
