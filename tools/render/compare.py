"""Several motion files as rows of one picture (``gesturecast render A.bvh B.bvh … --compare -o OUT.png``).

Every row is one file drawn at the same clip times (front and side, as :mod:`animation` draws a frame),
so generations of one speech with different styles can be compared frame by frame. Each row keeps its
own scale (the figure fills its panel); the row's label is the title of each of its frames.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image

from gesturecast.files import atomic_file
from gesturecast.tools.render.animation import contact_sheet, frame_caption, hips_subtree, sheet_indices
from gesturecast.tools.render.stick_figure import FigureConfig, FigureDrawer, hips_index, joint_sides, project_clip


@dataclass(frozen=True)
class CompareRow:
    label: str
    positions: np.ndarray  # (T, J, 3) from the chosen start
    parents: tuple[int, ...]
    names: tuple[str, ...]


def draw_row(row: CompareRow, indices: Sequence[int], fps: float, start_s: float,
             figure: FigureConfig) -> list[Image.Image]:
    """The row's frames at ``indices``, each titled with the row's label."""
    body, parents = hips_subtree(row.parents, hips_index(row.names))
    positions = row.positions[:, body]  # (T, J', 3)
    drawer = FigureDrawer(parents, joint_sides([row.names[j] for j in body]), figure, row.label)
    clip = project_clip(positions, figure)
    return [drawer.draw(clip, t, frame_caption(t, len(positions), fps, start_s)) for t in indices]


def render_comparison(rows: list[CompareRow], out_path: Path, fps: float, start_s: float = 0.0,
                      frames_per_row: int = 6, figure: FigureConfig | None = None) -> Path:
    """One PNG: a row of ``frames_per_row`` frames per file, at the same times (over the shortest file)."""
    figure = figure or FigureConfig()
    shortest = min(len(row.positions) for row in rows)
    indices = sheet_indices(shortest, frames_per_row)
    images = [image for row in rows for image in draw_row(row, indices, fps, start_s, figure)]
    sheet = contact_sheet(images, len(indices))
    with atomic_file(out_path, binary=True) as handle:
        sheet.save(handle, format="PNG")
    return out_path
