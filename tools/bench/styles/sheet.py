"""The picture of one held-out clip in a few styles at the default settings, body and face (``--sheet OUT.png``).

Every style is generated with the bundle's own guidance scale and the study's first seed on the study's speech
(the runs are shared with the rest of the study), then drawn by :func:`render_style_sheet`.
"""

from __future__ import annotations

from pathlib import Path

from gesturecast.frames import FACE_NAMES
from gesturecast.models.motion.motion import MOTION_FPS
from gesturecast.models.motion.skeleton import CANONICAL
from gesturecast.tools.bench.styles.runs import StudyRuns, label
from gesturecast.tools.render.compare import CompareRow
from gesturecast.tools.render.style_sheet import StyleRow, render_style_sheet

SHEET_STYLES = ("neutral", "happy", "old", "angry")
SHEET_START_S = 1.0  # the first second is the same idle pose in every style


def style_sheet(runs: StudyRuns, styles: tuple[str, ...], seed: int, out_path: Path) -> Path:
    first = int(SHEET_START_S * MOTION_FPS)
    rows = []
    for style in styles:
        generated = runs.generate(label(style, runs.bundle.default_guidance, seed))
        body = CompareRow(style, generated.positions[first:], CANONICAL.parents, CANONICAL.names)
        rows.append(StyleRow(body, generated.face[first:], FACE_NAMES["vrm0"]))
    return render_style_sheet(rows, out_path, MOTION_FPS, SHEET_START_S)
