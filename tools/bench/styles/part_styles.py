"""Per-part styles (GestureDiffuCLIP §6.3) against single-style generation on the same speech.

For a pair "``part`` = prompt, every other part = rest" at one guidance scale and seed:

- ``signatures``: for every body part of the per-part result, the distance of its :func:`part_signature` to
  the single-style run of its own prompt and to that of the other prompt, and its ``progress`` from the other
  prompt's run toward its own (1: the part moves as its own prompt moves a whole body);
- ``seams``: :func:`seam_roughness` of the per-part result and of the two single-style runs;
- ``metrics``: :func:`motion_metrics` of the per-part result and of the single-style runs;
- ``compute``: wall seconds per generated second, session setup excluded, of the base style alone and of
  the per-part request, generated afresh back to back ``TIMING_REPEATS`` times (median), with the rows of
  the batched denoiser call each needs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.models.motion.body_parts import PART_NAMES
from gesturecast.tools.bench.styles.measures import part_signature, seam_roughness, signature_distances
from gesturecast.tools.bench.styles.runs import StudyRuns, StyleRequest, label
from gesturecast.tools.eval.generate import Generated
from gesturecast.tools.eval.metrics import EvalNetworks, motion_metrics

TIMING_REPEATS = 3  # fresh generations per request for the compute cost (median)


@dataclass(frozen=True)
class PartPair:
    part: str  # the body part given its own prompt
    prompt: str  # its label
    rest: str  # the label of every other part (the base style)

    @property
    def name(self) -> str:
        return f"{self.part}={self.prompt}, rest={self.rest}"

    def own(self, part: str) -> str:
        return self.prompt if part == self.part else self.rest

    def other(self, part: str) -> str:
        return self.rest if part == self.part else self.prompt


DEFAULT_PAIRS = (PartPair("arms", "happy", "old"), PartPair("arms", "old", "happy"), PartPair("torso", "old", "angry"),
                 PartPair("legs", "old", "happy"))


def part_request(pair: PartPair, guidance: float, seed: int) -> StyleRequest:
    return StyleRequest(StylePrompt("label", pair.rest), guidance, ((pair.part, StylePrompt("label", pair.prompt)),),
                        seed)


def _signature(generated: Generated, part: str) -> np.ndarray:
    return part_signature(generated.rotations, generated.positions, part)


def part_signatures(pair: PartPair, result: Generated, single: dict[str, Generated]) -> dict:
    return {part: {"own": pair.own(part), **signature_distances(
        _signature(result, part), _signature(single[pair.own(part)], part), _signature(single[pair.other(part)], part))}
        for part in PART_NAMES}


def seams(result: Generated, single: dict[str, Generated]) -> dict:
    single_seams = {style: seam_roughness(g.rotations) for style, g in single.items()}
    return {"per_part": seam_roughness(result.rotations), "single_style": single_seams,
            "single_style_border_mean": float(np.mean([s["border"] for s in single_seams.values()]))}


def compute_cost(runs: StudyRuns, pair: PartPair, guidance: float, seed: int, repeats: int) -> dict:
    """Median real-time factors of the base style alone and of the per-part request, timed alternately."""
    requests = {"single_style": label(pair.rest, guidance, seed), "per_part": part_request(pair, guidance, seed)}
    times: dict[str, list[float]] = {kind: [] for kind in requests}
    for _ in range(repeats):
        for kind, request in requests.items():
            times[kind].append(runs.real_time_factor(request))
    return {"rtf": {kind: float(np.median(values)) for kind, values in times.items()},
            "denoiser_rows": {kind: runs.denoiser_rows(request) for kind, request in requests.items()}}


def pair_entry(runs: StudyRuns, networks: EvalNetworks, pair: PartPair, guidance: float, seed: int,
               timing_repeats: int) -> dict:
    single = {style: runs.generate(label(style, guidance, seed)) for style in (pair.prompt, pair.rest)}
    result, audio = runs.generate(part_request(pair, guidance, seed)), [runs.clip.audio]
    return {
        "pair": pair.name,
        "signatures": part_signatures(pair, result, single),
        "seams": seams(result, single),
        "metrics": {"per_part": motion_metrics([result.positions], audio, networks),
                    "single_style": {s: motion_metrics([g.positions], audio, networks) for s, g in single.items()}},
        "compute": compute_cost(runs, pair, guidance, seed, timing_repeats),
    }


def part_study(runs: StudyRuns, networks: EvalNetworks, pairs: tuple[PartPair, ...], guidance: float,
               seed: int, timing_repeats: int) -> dict:
    entries = [pair_entry(runs, networks, pair, guidance, seed, timing_repeats) for pair in pairs]
    closer = [part["closer_to_own"] for entry in entries for part in entry["signatures"].values()]
    prompted = {entry["pair"]: entry["signatures"][pair.part]["progress"] for entry, pair in zip(entries, pairs,
                                                                                                  strict=True)}
    return {
        "guidance": guidance,
        "seed": seed,
        "pairs": entries,
        "closer_to_own": {"parts": len(closer), "closer": int(sum(closer))},
        "prompted_part_progress": prompted,
        "seam_border_deg_per_frame2": {
            "per_part": float(np.mean([e["seams"]["per_part"]["border"] for e in entries])),
            "single_style": float(np.mean([e["seams"]["single_style_border_mean"] for e in entries]))},
        "rtf": {kind: float(np.mean([e["compute"]["rtf"][kind] for e in entries])) for kind in ("single_style",
                                                                                                "per_part")},
    }
