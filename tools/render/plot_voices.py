"""Picture of ``gesturecast bench voices``: speech loudness and generated upper-body speed, one row per voice.

Each row shares a time axis (seconds): the loudness (frame RMS dB, smoothed) on the left axis, the
generated motion's upper-body speed (m/s, smoothed) on the right one. Needs matplotlib (eval/dev extra).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gesturecast.files import save_figure

ROW_HEIGHT = 2.3
WIDTH = 13
DPI = 100


@dataclass(frozen=True)
class VoiceTrace:
    title: str
    loudness_db: np.ndarray  # (T,)
    speed: np.ndarray  # (T,) m/s
    fps: float


def plot_voice_traces(traces: list[VoiceTrace], out_path: Path, title: str) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(traces), 1, figsize=(WIDTH, ROW_HEIGHT * len(traces)), squeeze=False)
    for axis, trace in zip(axes[:, 0], traces, strict=True):
        seconds = np.arange(len(trace.speed)) / trace.fps
        axis.plot(seconds, trace.loudness_db, color="tab:blue", linewidth=1.0)
        axis.set_ylabel("loudness dB", color="tab:blue")
        speed_axis = axis.twinx()
        speed_axis.plot(seconds, trace.speed, color="tab:red", linewidth=1.2)
        speed_axis.set_ylabel("upper-body speed m/s", color="tab:red")
        speed_axis.set_ylim(bottom=0.0)
        axis.set_title(trace.title, fontsize=10)
        axis.set_xlim(0.0, seconds[-1] if len(seconds) else 1.0)
    axes[-1, 0].set_xlabel("time (s)")
    fig.suptitle(title)
    fig.tight_layout()
    save_figure(fig, out_path, dpi=DPI)
    plt.close(fig)
    return out_path
