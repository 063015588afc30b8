"""Render joint positions to a GIF, an MP4 (through ffmpeg) or a PNG contact sheet.

`render_positions` is the one entry point; the output format follows the file suffix:

- ``.gif``: every `stride`-th frame, played at the clip's speed, looping;
- ``.mp4``: the same frames piped as raw RGB to the ``ffmpeg`` found on PATH (H.264, yuv420p);
- ``.png``: a contact sheet, a grid of `sheet_frames` evenly spaced frames.
"""

from __future__ import annotations

import logging
import shutil
import subprocess
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from PIL import Image

from gesturecast.errors import UserError
from gesturecast.files import atomic_file, atomic_path
from gesturecast.tools.render.stick_figure import (
    BACKGROUND,
    FigureConfig,
    FigureDrawer,
    hips_index,
    joint_sides,
    project_clip,
)

log = logging.getLogger(__name__)

SUFFIXES = (".gif", ".mp4", ".png")
GIF_TIME_UNIT_MS = 10  # GIF frame delays are stored in hundredths of a second
SHEET_GAP_PX = 4


@dataclass(frozen=True)
class RenderConfig:
    figure: FigureConfig = field(default_factory=FigureConfig)
    stride: int = 1  # draw every stride-th frame (GIF / MP4)
    sheet_frames: int = 12  # frames on a PNG contact sheet
    sheet_columns: int = 4
    start_s: float = 0.0  # clip time of the first frame (the captions show clip time)
    focus: str | None = None  # draw only this joint and the joints under it, followed and zoomed (e.g. LeftLowerArm)


def render_positions(
    positions: np.ndarray,
    parents: Sequence[int],
    out_path: str | Path,
    fps: float = 30.0,
    title: str = "",
    names: Sequence[str] | None = None,
    config: RenderConfig | None = None,
) -> Path:
    """Draw a clip of joint positions (T, J, 3) (Y-up, faces +Z) from the front and the side.

    parents: parent index per joint (-1 for the root, which must be joint 0). names, when given,
    colour the character's left limbs blue and right limbs red and pick the hips joint (else
    joint 0), which is followed in the ground plane; joints above it are not drawn. Returns the
    written path.
    """
    config = config or RenderConfig()
    out_path = Path(out_path)
    _check_inputs(positions, parents, out_path, config)
    root = focus_index(names, config.focus) if config.focus else hips_index(names)
    body, parents = hips_subtree(parents, root)
    positions = positions[:, body]  # (T, J', 3): a floor-level root above the hips (Bandai) is left out
    sides = joint_sides([names[j] for j in body]) if names is not None else np.zeros(len(body), dtype=int)
    drawer = FigureDrawer(parents, sides, config.figure, title)
    clip = project_clip(positions, config.figure, follow_height=config.focus is not None)
    num_frames = positions.shape[0]

    def caption(t: int) -> str:
        return frame_caption(t, num_frames, fps, config.start_s)

    if out_path.suffix == ".png":
        indices = sheet_indices(num_frames, config.sheet_frames)
        sheet = contact_sheet([drawer.draw(clip, t, caption(t)) for t in indices], config.sheet_columns)
        with atomic_file(out_path, binary=True) as handle:
            sheet.save(handle, format="PNG")
        return out_path
    indices = range(0, num_frames, config.stride)
    frames = (drawer.draw(clip, t, caption(t)) for t in indices)
    frame_fps = fps / config.stride
    if out_path.suffix == ".gif":
        write_gif(frames, out_path, gif_delays_ms(len(indices), frame_fps))
    else:
        write_mp4(frames, out_path, frame_fps, config.figure.image_size)
    return out_path


def frame_caption(index: int, num_frames: int, fps: float, start_s: float = 0.0) -> str:
    """The caption under drawn frame ``index``: its number in the drawn range and its time in the clip."""
    return f"frame {index + 1}/{num_frames}   {start_s + index / fps:6.2f} s"


def _check_inputs(positions: np.ndarray, parents: Sequence[int], out_path: Path, config: RenderConfig) -> None:
    if out_path.suffix not in SUFFIXES:
        raise UserError(f"cannot render to '{out_path.name}': use a file name ending in {', '.join(SUFFIXES)}")
    if positions.ndim != 3 or positions.shape[-1] != 3 or positions.shape[1] != len(parents):
        raise ValueError(f"positions must be (T, {len(parents)}, 3), got {positions.shape}")
    if positions.shape[0] == 0:
        raise UserError("nothing to render: the clip has no frames")
    if not np.isfinite(positions).all():
        raise UserError("cannot render: the joint positions contain NaN or infinite values")
    if parents[0] != -1 or config.stride < 1:
        raise ValueError("joint 0 must be the root (parent -1) and stride must be >= 1")
    if out_path.suffix == ".mp4" and shutil.which("ffmpeg") is None:
        raise UserError("ffmpeg is not on PATH: install it (e.g. apt-get install ffmpeg) or render to .gif / .png")
    if not out_path.parent.is_dir():
        raise UserError(f"output folder {out_path.parent} does not exist")


def focus_index(names: Sequence[str] | None, focus: str) -> int:
    """The index of the joint named ``focus``; UserError naming the joints there are if none is."""
    if names is None or focus not in names:
        known = ", ".join(names or ()) or "none (the clip has no joint names)"
        raise UserError(f"--focus {focus}: no such joint; joints: {known}")
    return list(names).index(focus)


def hips_subtree(parents: Sequence[int], hips: int) -> tuple[list[int], list[int]]:
    """The joints under `hips` (itself included, in order) and their parent indices within that subset."""
    body: list[int] = []
    for j, parent in enumerate(parents):
        if j == hips or parent in body:
            body.append(j)
    return body, [body.index(parents[j]) if j != hips else -1 for j in body]


def sheet_indices(num_frames: int, count: int) -> list[int]:
    """`count` evenly spaced frame indices from first to last (fewer when the clip is shorter)."""
    return sorted(set(np.linspace(0, num_frames - 1, min(count, num_frames)).round().astype(int).tolist()))


def contact_sheet(images: Sequence[Image.Image], columns: int) -> Image.Image:
    """Tile equally sized images row by row, `columns` per row, on the background colour."""
    width, height = images[0].size
    columns = min(columns, len(images))
    rows = -(-len(images) // columns)
    sheet = Image.new("RGB", (columns * (width + SHEET_GAP_PX), rows * (height + SHEET_GAP_PX)), (255, 255, 255))
    for i, image in enumerate(images):
        row, column = divmod(i, columns)
        sheet.paste(image.convert("RGB"), (column * (width + SHEET_GAP_PX), row * (height + SHEET_GAP_PX)))
    return sheet


def gif_delays_ms(count: int, fps: float) -> list[int]:
    """Per-frame delays in GIF's 10 ms unit whose running sum tracks k / fps (e.g. 30, 40, 30 at 30 fps)."""
    ends = np.round(np.arange(1, count + 1) * 1000.0 / fps / GIF_TIME_UNIT_MS)  # frame end times, 10 ms units
    delays = np.diff(ends, prepend=0.0) * GIF_TIME_UNIT_MS
    return np.maximum(delays, GIF_TIME_UNIT_MS).astype(int).tolist()


def write_gif(frames: Iterator[Image.Image], out_path: Path, delays_ms: list[int]) -> None:
    """A looping GIF of palette frames, one delay per frame (written atomically)."""
    first = next(frames)
    with atomic_file(out_path, binary=True) as handle:
        first.save(handle, format="GIF", save_all=True, append_images=frames, duration=delays_ms, loop=0,
                   background=BACKGROUND, optimize=False)


def write_mp4(frames: Iterator[Image.Image], out_path: Path, fps: float, size: tuple[int, int]) -> None:
    """Pipe raw RGB frames into ffmpeg (H.264, yuv420p, plays everywhere), which writes a temporary file
    that replaces ``out_path`` only when ffmpeg succeeded."""
    with atomic_path(out_path) as temp:
        command = [
            "ffmpeg", "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{size[0]}x{size[1]}",
            "-r", f"{fps:g}", "-i", "-", "-pix_fmt", "yuv420p", "-vcodec", "libx264", "-f", "mp4", str(temp),
        ]  # fmt: skip
        process = subprocess.Popen(command, stdin=subprocess.PIPE, stderr=subprocess.PIPE)
        try:
            for frame in frames:
                process.stdin.write(frame.convert("RGB").tobytes())
        except BrokenPipeError:
            log.debug("ffmpeg closed its input early")
        _, stderr = process.communicate()
        if process.returncode != 0:
            raise UserError(f"ffmpeg failed writing {out_path}: {stderr.decode(errors='replace').strip()[-300:]}")
