"""The frozen FGD motion encoder (numpy only) and the Fréchet Gesture Distance through it.

FGD (Yoon et al. 2020, Sec. 5.1) = the Fréchet distance (:mod:`.frechet`) between the encoder
features of real and of generated motion windows (:mod:`.eval_windows`: 64 frames of
root-relative joint positions, every 16 frames). The weights file is versioned: numbers are
comparable only between runs with the same ``version`` (recorded in every evaluation JSON); the file
is replaced only deliberately, with a new version number and file name.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

from gesturecast.models.evaluation.convnet import EvalConvNet, read_stamp
from gesturecast.models.evaluation.frechet import frechet_distance
from gesturecast.models.evaluation.windows import clips_windows

FGD_ENCODER_VERSION = 1
EVAL_WEIGHTS_DIR = Path(str(resources.files("gesturecast.models"))) / "weights" / "eval"
DEFAULT_FGD_ENCODER = EVAL_WEIGHTS_DIR / f"fgd_encoder_v{FGD_ENCODER_VERSION}.npz"


@dataclass(frozen=True)
class FGDEncoder:
    net: EvalConvNet
    stamp: dict

    @classmethod
    def load(cls, path: Path | str = DEFAULT_FGD_ENCODER) -> FGDEncoder:
        stamp = read_stamp(path)
        return cls(EvalConvNet.load(path), stamp)

    @property
    def version(self) -> int:
        return int(self.stamp["version"])

    def features(self, clips: list[np.ndarray]) -> np.ndarray:
        """Encoder features (N, D) of every window of clips of positions (T, J, 3)."""
        return self.net.forward(clips_windows(clips, self.net.config.window))

    def fgd(self, real: list[np.ndarray], generated: list[np.ndarray]) -> float:
        """FGD between two sets of clips (positions (T, J, 3) each); each set needs ≥ 2 windows."""
        return frechet_distance(self.features(real), self.features(generated))
