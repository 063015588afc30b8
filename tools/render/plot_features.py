"""Picture of the speech features under the waveform: ``python -m gesturecast.tools.render.plot_features IN OUT.png``.

Rows (shared 30 fps time axis): waveform, log-mel image, onset strength, energy (dBFS),
speaking flag. Needs matplotlib (a dev/eval extra), not part of the runtime path.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from gesturecast.files import save_figure
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.audio.streaming import FeatureConfig, extract_features

ROW_HEIGHTS = (1.2, 2.0, 0.8, 0.8, 0.5)
FIGURE_SIZE = (14, 8)
DPI = 110


def plot_features(audio_path: Path, out_path: Path, start_s: float, seconds: float) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    config = FeatureConfig()
    audio = load_audio(audio_path)
    features = extract_features(audio, config)
    first, count = int(start_s * config.fps), int(seconds * config.fps)
    frames = features[first : first + count]  # (T, F)
    clip = audio[int(start_s * SAMPLE_RATE) : int((start_s + seconds) * SAMPLE_RATE)]
    frame_t = (first + np.arange(frames.shape[0]) + 1) / config.fps  # each frame at its end time
    layout = config.layout
    fig, axes = plt.subplots(5, 1, figsize=FIGURE_SIZE, sharex=True, gridspec_kw={"height_ratios": ROW_HEIGHTS})
    axes[0].plot(start_s + np.arange(clip.shape[0]) / SAMPLE_RATE, clip, linewidth=0.4)
    axes[0].set_ylabel("waveform")
    axes[1].imshow(frames[:, layout["mel"]].T, origin="lower", aspect="auto", cmap="magma",
                   extent=(start_s, start_s + frames.shape[0] / config.fps, 0, config.n_mels))
    axes[1].set_ylabel(f"log-mel ({config.n_mels})")
    axes[2].plot(frame_t, frames[:, layout["onset"]], color="tab:green")
    axes[2].set_ylabel("onset (dB)")
    axes[3].plot(frame_t, frames[:, layout["energy"]], color="tab:orange")
    axes[3].set_ylabel("energy dBFS")
    axes[4].fill_between(frame_t, frames[:, layout["speaking"]][:, 0], step="pre", color="tab:red", alpha=0.6)
    axes[4].set_ylabel(f"speaking ({config.vad.method})")
    axes[4].set_xlabel("time (s)")
    fig.suptitle(f"{audio_path.name}: features at {config.fps} fps")
    fig.tight_layout()
    save_figure(fig, out_path, dpi=DPI)
    plt.close(fig)
    return out_path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("audio", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--start", type=float, default=0.0, help="seconds")
    parser.add_argument("--seconds", type=float, default=12.0)
    args = parser.parse_args(argv)
    plot_features(args.audio, args.out, args.start, args.seconds)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
