"""Calibrate the size of each fitted style against the real styled takes, on the judge's FK window features.

``fit.fit_styles`` takes the median change over the actions, per body part; what a style then does to a whole
motion (its posture through the joint chain, its gestures through the gain) need not be the size of what the real
takes show. For each style, the posture (``offset``) and the gain (``log_gain``) are each scaled by one factor of
:data:`SCALES`, chosen so that the stylizer, re-performing each action's neutral take, lands nearest the real take
of that action in that style: the squared distance of the two takes' mean window features
(``descriptors.window_features``, logged as the judge reads them), each feature over the spread of that action's
real takes, summed over the actions. A gain factor is allowed only if the re-performed takes' mean jerk stays at
most what the fitted gain gives them with the same posture (a gain below 1 that the tension's enlargement already
offsets would otherwise grow toward 1: angry reached 1.58x the jerk of real motion on speech). The tempo and
tension are left as fitted. The calibration is checked on actions it never saw by ``style-fit``'s
``held_out_actions`` report.
"""

from __future__ import annotations

import itertools

import numpy as np

from gesturecast.models.evaluation.metrics import jerk, root_relative
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.models.style.descriptors import window_features
from gesturecast.models.style.judge import logged_features
from gesturecast.models.style.params import LOG_GAIN, OFFSET, StyleParams
from gesturecast.tools.style.fit import fit_styles, restyled_rotations
from gesturecast.tools.style.takes import NEUTRAL, Take

SCALES = (0.25, 0.5, 0.75, 1.0, 1.5, 2.0)


def _mean_features(take: Take, rotations: np.ndarray) -> np.ndarray:
    """(F,) mean logged window features of a take with these rotations (T, J, 4)."""
    return logged_features(window_features(rotations, take.motion.root_position, take.motion.fps)).mean(axis=0)


def _jerk(take: Take, rotations: np.ndarray) -> float:
    """GENEA jerk (m/s³) of the take's root-relative joint positions with these rotations (T, J, 4)."""
    _, positions = CANONICAL.forward_kinematics(rotations[:, :CANONICAL.num_joints], take.motion.root_position)
    return jerk(root_relative(positions), take.motion.fps)


class RealTargets:
    """Per action its neutral take, its real takes' mean features per style and its features' spread (F,)."""

    def __init__(self, takes: list[Take]) -> None:
        self.neutral: dict[str, Take] = {}
        self.means: dict[tuple[str, str], np.ndarray] = {}
        self.spread: dict[str, np.ndarray] = {}
        for content in sorted({take.content for take in takes}):
            mine = {take.style: take for take in takes if take.content == content}  # the first take of each style
            if NEUTRAL not in mine or len(mine) < 2:
                continue
            self.neutral[content] = mine[NEUTRAL]
            features = {style: logged_features(window_features(take.motion.rotations, take.motion.root_position,
                                                               take.motion.fps)) for style, take in mine.items()}
            self.spread[content] = np.concatenate(list(features.values())).std(axis=0) + 1e-6
            self.means.update({(content, style): f.mean(axis=0) for style, f in features.items()})

    def error(self, style: str, values: np.ndarray) -> tuple[float, float]:
        """Σ over the actions with ``style`` of |(styled neutral − real styled) / spread|² (mean features), and the
        re-performed neutral takes' mean jerk."""
        total, jerks = 0.0, []
        for content, neutral in self.neutral.items():
            if (content, style) in self.means:
                rotations = restyled_rotations(neutral, values)  # (T, J, 4)
                styled = _mean_features(neutral, rotations)
                total += float(np.sum(((styled - self.means[(content, style)]) / self.spread[content]) ** 2))
                jerks.append(_jerk(neutral, rotations))
        return total, float(np.mean(jerks))


def scaled(values: np.ndarray, offset: float, gain: float = 1.0) -> np.ndarray:
    """A copy of style parameters (S, CHANNELS) with the posture offsets × ``offset`` and the log gains × ``gain``."""
    out = values.copy()
    out[:, OFFSET] *= offset
    out[:, LOG_GAIN] *= gain
    return out


def calibrate(styles: dict[str, StyleParams], takes: list[Take]) -> tuple[dict[str, StyleParams], dict]:
    """Every style with its posture and gain scaled to the real takes (module docstring), and the scales chosen."""
    targets = RealTargets(takes)
    out, chosen = {}, {}
    for style, params in styles.items():
        if params.is_identity:
            out[style] = params
            continue
        measured = {pair: targets.error(style, scaled(params.values, *pair))
                    for pair in itertools.product(SCALES, SCALES)}  # (offset, gain) -> (error, jerk)
        allowed = [(offset, gain) for offset, gain in measured
                   if measured[(offset, gain)][1] <= measured[(offset, 1.0)][1]]  # no more jerk than the fitted gain
        best = min(allowed, key=lambda pair: measured[pair][0])
        fitted_error, fitted_jerk = measured[(1.0, 1.0)]
        out[style] = StyleParams(scaled(params.values, *best))
        chosen[style] = {"offset_scale": best[0], "gain_scale": best[1], "error": round(measured[best][0], 2),
                         "error_unscaled": round(fitted_error, 2), "jerk": round(measured[best][1], 1),
                         "jerk_unscaled": round(fitted_jerk, 1)}
    return out, chosen


def fit_calibrated(takes: list[Take]) -> tuple[dict[str, StyleParams], dict]:
    """``fit.fit_styles`` then :func:`calibrate` on the same takes; the report gains each style's ``calibration``."""
    styles, report = fit_styles(takes)
    styles, chosen = calibrate(styles, takes)
    for style, scales in chosen.items():
        report[style]["calibration"] = scales
    return styles, report
