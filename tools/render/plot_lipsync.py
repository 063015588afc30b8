"""Picture of the viseme weights above the loudness: ``python -m gesturecast.tools.render.plot_lipsync IN OUT.png``.

Rows (shared 30 fps time axis, each frame at its end time): the five weights stacked (their sum is the
mouth opening), the frame's RMS level in dBFS with the speaking flag shaded. Needs matplotlib (dev/eval extra).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from gesturecast.files import save_figure
from gesturecast.frames import VISEME_NAMES
from gesturecast.models.audio.files import load_audio
from gesturecast.models.audio.lipsync import LipSyncConfig
from gesturecast.models.audio.streaming import FeatureConfig, StreamingFeatureExtractor, speaking_flags

FIGURE_SIZE = (14, 5.5)
DPI = 110
VISEME_COLORS = ("tab:red", "tab:blue", "tab:green", "tab:orange", "tab:purple")


def plot_lipsync(audio_path: Path, out_path: Path, start_s: float, seconds: float) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    config = FeatureConfig()
    extractor = StreamingFeatureExtractor(config, LipSyncConfig())
    features = extractor.push(load_audio(audio_path))  # (T, F)
    first, count = int(start_s * config.fps), int(seconds * config.fps)
    weights = extractor.take_visemes()[first : first + count]  # (T, 5)
    frames = features[first : first + count]
    frame_t = (first + np.arange(len(frames)) + 1) / config.fps
    fig, axes = plt.subplots(2, 1, figsize=FIGURE_SIZE, sharex=True, gridspec_kw={"height_ratios": (2.0, 1.0)})
    axes[0].stackplot(frame_t, weights.T, labels=VISEME_NAMES["vrm0"], colors=VISEME_COLORS, step="pre")
    axes[0].set_ylim(0.0, 1.0)
    axes[0].set_ylabel("viseme weights (sum = opening)")
    axes[0].legend(loc="upper right", ncol=5)
    axes[1].plot(frame_t, frames[:, config.layout["energy"]], color="black", linewidth=0.8)
    speaking = speaking_flags(frames, config)
    axes[1].fill_between(frame_t, -100, 0, where=speaking, step="pre", color="tab:red", alpha=0.15,
                         label="speaking")
    axes[1].set_ylim(-80, -5)
    axes[1].set_ylabel("frame RMS dBFS")
    axes[1].legend(loc="lower right")
    axes[1].set_xlabel("time (s)")
    fig.suptitle(f"{audio_path.name}: lip sync at {config.fps} fps")
    fig.tight_layout()
    save_figure(fig, out_path, dpi=DPI)
    plt.close(fig)
    return out_path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("audio", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--start", type=float, default=0.0, help="seconds")
    parser.add_argument("--seconds", type=float, default=5.0)
    args = parser.parse_args(argv)
    plot_lipsync(args.audio, args.out, args.start, args.seconds)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
