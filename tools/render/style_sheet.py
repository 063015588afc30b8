"""One speech in several styles, body and face: a row per style (``gesturecast bench styles --sheet OUT.png``).

Each row is one style's motion drawn at the same clip times (front and side, as :mod:`compare` draws them),
followed by a panel of its face over the clip: the blink of both eyes and every emotion preset's weight
(realtime/pose/face.py), with the drawn frames' times marked. All panels have the frame images' size, so the
rows tile into one PNG.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image

from gesturecast.files import atomic_file
from gesturecast.tools.render.animation import contact_sheet, sheet_indices
from gesturecast.tools.render.compare import CompareRow, draw_row
from gesturecast.tools.render.stick_figure import FigureConfig

DPI = 100
BLINK_COLUMN = 0  # FACE_NAMES: both eyes' blink first, then each eye's, then the presets
FIRST_PRESET_COLUMN = 3


@dataclass(frozen=True)
class StyleRow:
    body: CompareRow
    face: np.ndarray  # (T, 8) weights in FACE_NAMES order, from the same start as the body
    face_names: tuple[str, ...]


def face_panel(row: StyleRow, marks: Sequence[int], fps: float, start_s: float, size: tuple[int, int]) -> Image.Image:
    """The row's blink and expression weights against time, the drawn frames marked, at ``size`` pixels."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axis = plt.subplots(figsize=(size[0] / DPI, size[1] / DPI), dpi=DPI, layout="constrained")
    times = start_s + np.arange(len(row.face)) / fps  # (T,)
    axis.plot(times, row.face[:, BLINK_COLUMN], color="0.6", linewidth=0.8, label=row.face_names[BLINK_COLUMN])
    for column in range(FIRST_PRESET_COLUMN, row.face.shape[1]):
        axis.plot(times, row.face[:, column], linewidth=1.6, label=row.face_names[column])
    for mark in marks:
        axis.axvline(start_s + mark / fps, color="0.85", linewidth=0.8, zorder=0)
    axis.set_ylim(-0.02, 1.02)
    axis.set_xlabel("s", fontsize=7)
    axis.set_title(f"{row.body.label}: face", fontsize=8)
    axis.tick_params(labelsize=6)
    axis.legend(fontsize=5, loc="upper right", ncol=2)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=DPI)
    plt.close(fig)
    buffer.seek(0)
    return Image.open(buffer).convert("RGB").resize(size)


def render_style_sheet(rows: list[StyleRow], out_path: Path, fps: float, start_s: float = 0.0,
                       frames_per_row: int = 4, figure: FigureConfig | None = None) -> Path:
    """One PNG: per style ``frames_per_row`` body frames at the same times, then its face panel."""
    figure = figure or FigureConfig()
    shortest = min(len(row.body.positions) for row in rows)
    indices = sheet_indices(shortest, frames_per_row)
    images = []
    for row in rows:
        images += draw_row(row.body, indices, fps, start_s, figure)
        images.append(face_panel(row, indices, fps, start_s, figure.image_size))
    sheet = contact_sheet(images, len(indices) + 1)
    with atomic_file(out_path, binary=True) as handle:
        sheet.save(handle, format="PNG")
    return out_path
