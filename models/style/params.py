"""A style as a few numbers per upper-body joint, and the causal filter that reads and applies them.

The stylizer (``gesturecast.realtime.pose.stylizer``) re-performs the generator's motion in a style after the
generator has decided *what* to do and *when*. It works on each styled joint's local rotation as a rotation
vector v = log(q) (identity = T-pose). A style changes, per joint (the idea of EMOTE, Chi et al. 2000: effort and
shape as parameters on top of a motion):

- **amplitude** ``log_gain``: v is scaled by exp(log_gain) about a pivot p, with no delay: for the arms the rest
  pose r (arms relaxed at the sides): bigger, more expansive gestures or smaller ones held closer to the body; for
  the torso and head the slow centre m (below): their movement about it, so that their posture is the offset's
  alone, whatever posture the motion comes in (a speaker's spine and neck are bent otherwise than an actor's, and a
  gain about r would bend them the other way);
- **posture** ``offset`` (3, radians): added after (lean, head pitch, shoulders, arm carriage);
- **tempo and tension** ``tension`` α on the gesture d = v − m about a slow centre m (an exponential moving
  average, time constant :data:`CENTRE_S`), with one-pole low-passes L (:data:`TENSION_S`) and L'
  (:data:`JITTER_S`): α < 0 adds α·(d − L(d)), slower and smoother (−1 leaves L(d): sluggish, late); α > 0 adds
  α·(L'(d) − L(d)), quicker, crisper accents from the band between them, so the frame-to-frame jitter above it is
  not amplified. A causal filter cannot play motion faster than it arrives, so tempo is changed by the filter,
  not by a time warp;
- **tremor** (radians): a small deterministic 5–7 Hz oscillation (a function of stream time only).

Every number is fitted from content-paired takes (the same action in the style and in ``neutral``:
``gesturecast.tools.style.fit``). Styles mix linearly in this space (γ mixes, text weights, per-part choices),
and a strength k scales a style from the identity (k = 0: the input motion) to twice the fitted change.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

from gesturecast.models.motion.body_parts import ARM_JOINTS, PART_JOINTS, TORSO_JOINTS
from gesturecast.models.motion.rotations import quat_from_axis_angle, quat_to_axis_angle
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.models.style.fitted_file import read_fitted, write_fitted

STYLED_JOINTS = TORSO_JOINTS + ARM_JOINTS  # the legs and hips stay as generated (feet stay planted)
STYLED_INDEX = np.array([CANONICAL.index(name) for name in STYLED_JOINTS])  # (S,) canonical joint indices
ABOUT_CENTRE = np.array([name in TORSO_JOINTS for name in STYLED_JOINTS])  # (S,) scaled about m, the rest about r
OFFSET, LOG_GAIN, TENSION, TREMOR = slice(0, 3), 3, 4, 5
CHANNELS = 6  # offset xyz, log gain, tension, tremor per styled joint
CENTRE_S = 1.0  # time constant of the posture centre m
TENSION_S = 0.12  # time constant of the tension filter's low-pass L
JITTER_S = 0.03  # ... and of L', above which a sharper style amplifies nothing
TREMOR_HZ = np.array([5.3, 6.1, 6.9])  # one frequency per axis
FORMAT = "gesturecast-style-params-1"
DEFAULT_STYLE_PARAMS = Path(str(resources.files("gesturecast.models"))) / "weights" / "stylizer" / "styles.json"


def ema_weight(time_constant_s: float, fps: float) -> float:
    """Per-frame weight a of an exponential moving average m += a·(x − m) with this time constant."""
    return float(1.0 - np.exp(-1.0 / (time_constant_s * fps)))


@dataclass(frozen=True)
class StyleParams:
    """One style: ``values`` (S, CHANNELS) over :data:`STYLED_JOINTS` (module docstring); zeros = no change."""

    values: np.ndarray

    @staticmethod
    def identity() -> StyleParams:
        return StyleParams(np.zeros((len(STYLED_JOINTS), CHANNELS)))

    def scaled(self, strength: float) -> StyleParams:
        """The style at ``strength`` k: every change × k (gains as exp(k·log_gain))."""
        return StyleParams(self.values * strength)

    @property
    def is_identity(self) -> bool:
        return not self.values.any()


def mix(params: list[StyleParams], weights: list[float]) -> StyleParams:
    """Σ wᵢ·paramsᵢ (weights need not sum to 1: γ > 1 extrapolates)."""
    return StyleParams(sum(w * p.values for w, p in zip(weights, params, strict=True)))


def part_rows(part: str) -> np.ndarray:
    """(S,) mask of the styled joints of a body part (``arms``, ``torso``, ``legs``: none styled)."""
    joints = set(PART_JOINTS[part])
    return np.array([name in joints for name in STYLED_JOINTS])


class StyleBook:
    """Fitted styles by label, read from a JSON file written by the fit (``neutral`` is the identity)."""

    def __init__(self, styles: dict[str, StyleParams], meta: dict) -> None:
        self.styles = styles
        self.meta = meta

    @property
    def labels(self) -> tuple[str, ...]:
        return tuple(sorted(self.styles))

    def get(self, label: str) -> StyleParams | None:
        return self.styles.get(label)

    def save(self, path: Path) -> None:
        data = {"format": FORMAT, "joints": list(STYLED_JOINTS), **self.meta,
                "styles": {name: np.round(p.values, 5).tolist() for name, p in sorted(self.styles.items())}}
        write_fitted(path, data)

    @staticmethod
    def labels_left(path: Path, labels: tuple[str, ...]) -> frozenset[str]:
        """Those of ``labels`` that the style-parameter file does not give."""
        return frozenset(labels) - set(StyleBook.load(path).styles)

    @staticmethod
    def load(path: Path) -> StyleBook:
        data = read_fitted(path, "style-parameter file", FORMAT, "joints", STYLED_JOINTS)
        styles = {name: StyleParams(np.asarray(rows, dtype=np.float64)) for name, rows in data["styles"].items()}
        meta = {key: value for key, value in data.items() if key not in ("format", "joints", "styles")}
        return StyleBook(styles, meta)


class StyleFilter:
    """The causal state of one stream's styled joints: the centre m and the tension low-passes (module docstring).

    :meth:`run` takes a run of frames' rotation vectors v (n, S, 3) and their (n, S, CHANNELS) parameters and returns
    the styled rotation vectors. The state follows the *input* only (first-order recursions along time, their last
    outputs carried from call to call, so any split of a stream into runs gives the same bits), and changing the
    parameters never disturbs it. ``rest`` (S, 3) are the rest pose's rotation vectors, the arms' pivot of the
    amplitude change (:func:`pivots`)."""

    def __init__(self, fps: float, rest: np.ndarray) -> None:
        self.fps = fps
        self.rest = rest  # (S, 3) rotation vectors of the rest pose
        self._weights = {name: ema_weight(seconds, fps) for name, seconds in
                         (("centre", CENTRE_S), ("low", TENSION_S), ("band", JITTER_S))}
        self.reset()

    def reset(self) -> None:
        self._state: dict[str, np.ndarray] | None = None  # filter name -> (S, 3) its last output

    def _smooth(self, name: str, x: np.ndarray) -> np.ndarray:
        """x (n, S, 3) through the named one-pole low-pass m_t = m_{t-1} + a·(x_t − m_{t-1}), along time.

        A loop over frames: a stream's runs are a few frames long, and ``scipy.signal.lfilter`` would cost every
        command half a second of start-up for the import."""
        a, last = self._weights[name], self._state[name]  # last: (S, 3)
        y = np.empty_like(x)  # (n, S, 3)
        for t, frame in enumerate(x):
            last = last + a * (frame - last)
            y[t] = last
        self._state[name] = last
        return y

    def run(self, v: np.ndarray, values: np.ndarray, times: np.ndarray) -> np.ndarray:
        """Styled rotation vectors (n, S, 3) of frames v (n, S, 3) with parameters (n, S, CHANNELS) at times (n,)."""
        if self._state is None:  # the first frame starts every filter settled: centre = v_0, gesture 0
            self._state = {"centre": v[0], "low": np.zeros_like(v[0]), "band": np.zeros_like(v[0])}
        centre = self._smooth("centre", v)  # (n, S, 3) the slow centre m
        deviation = v - centre  # (n, S, 3) the gesture d about it
        low, band = self._smooth("low", deviation), self._smooth("band", deviation)
        alpha = values[..., TENSION, None]  # (n, S, 1)
        tense = alpha * (np.where(alpha > 0.0, band, deviation) - low)  # (n, S, 3) the tension's change
        tremor = values[..., TREMOR, None] * np.sin(2.0 * np.pi * TREMOR_HZ * times[:, None, None])  # (n, S, 3)
        gain = np.exp(values[..., LOG_GAIN, None])  # (n, S, 1)
        pivot = pivots(self.rest, centre)  # (n, S, 3)
        return pivot + gain * (v + tense - pivot) + values[..., OFFSET] + tremor


def pivots(rest: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """(n, S, 3) the amplitude's pivot per frame: the centre m (n, S, 3) for the torso and head, ``rest`` (S, 3) for
    the arms (module docstring)."""
    return np.where(ABOUT_CENTRE[:, None], centre, rest)


def rotation_vectors(rotations: np.ndarray) -> np.ndarray:
    """Styled joints' rotation vectors (..., S, 3) of canonical rotations (..., J, 4)."""
    return quat_to_axis_angle(rotations[..., STYLED_INDEX, :])


def with_rotation_vectors(rotations: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """A copy of canonical rotations (..., J, 4) whose styled joints are exp(vectors (..., S, 3))."""
    out = rotations.copy()
    out[..., STYLED_INDEX, :] = quat_from_axis_angle(vectors)
    return out
