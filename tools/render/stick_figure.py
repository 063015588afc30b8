"""Draw a skeleton as a stick figure, seen from the front and from the side, with Pillow.

Conventions (docs/architecture.md): Y-up, the character faces +Z, its left is +X. The front panel looks at
the character from +Z (its left appears on the viewer's right); the side panel looks from the
character's right (-X), so it faces to the right of the picture. The root is followed in the
ground plane (X, Z) so the figure stays centred; vertical motion is kept, over a ground line at Y = 0.

Frames are drawn as palette ("P") images with a fixed palette, which GIF stores directly.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from PIL import Image, ImageDraw, ImageFont

# palette: index -> RGB
BACKGROUND, GROUND, CENTRE, LEFT, RIGHT, TEXT, JOINT, DIVIDER = range(8)
PALETTE_RGB: tuple[tuple[int, int, int], ...] = (
    (250, 250, 247),  # background
    (150, 150, 150),  # ground line
    (70, 70, 70),  # midline bones (spine, neck, head)
    (35, 105, 215),  # the character's left limbs (blue)
    (215, 60, 40),  # the character's right limbs (red)
    (20, 20, 20),  # text
    (25, 25, 25),  # joint dots
    (205, 205, 205),  # panel divider
)
SIDE_COLOURS = {-1: RIGHT, 0: CENTRE, 1: LEFT}
PANEL_NAMES = ("front", "side")

# "left" anywhere, "_L" / ".L" suffixes, "l_" prefix (any case); CMU's "LHipJoint" (case-sensitive, not "LowerBack")
_LEFT_NAME = re.compile(r"(?i:left|_l$|\.l$|^l_)|^L[A-Z]")
_RIGHT_NAME = re.compile(r"(?i:right|_r$|\.r$|^r_)|^R[A-Z]")
_HIPS_NAME = re.compile(r"hips|pelvis", re.IGNORECASE)


@dataclass(frozen=True)
class FigureConfig:
    """Picture geometry in pixels. Sizes are even so that yuv420p video accepts them."""

    panel_width: int = 240
    panel_height: int = 300
    header_px: int = 20  # title line above the panels
    footer_px: int = 18  # frame counter below the panels
    margin_px: int = 14  # empty border inside each panel around the figure
    bone_width_px: int = 3
    joint_radius_px: int = 2

    @property
    def image_size(self) -> tuple[int, int]:
        return 2 * self.panel_width, self.header_px + self.panel_height + self.footer_px


def joint_sides(names: Sequence[str]) -> np.ndarray:
    """+1 for the character's left joints, -1 for the right, 0 for the midline, from the joint names.

    Knows Unity/Mixamo ("LeftHand"), Bandai ("Hand_L"), SMPL-X ("left_wrist") and CMU ("LHipJoint").
    """
    return np.array([1 if _LEFT_NAME.search(n) else -1 if _RIGHT_NAME.search(n) else 0 for n in names])


@dataclass(frozen=True)
class ProjectedClip:
    """Screen coordinates of every joint in both panels.

    pixels: (T, 2, J, 2) float pixel (x, y) per frame, panel (front, side), joint.
    depth: (T, 2, J) distance along each panel's viewing direction (larger = farther).
    ground_y: pixel row of the ground line (Y = 0); None when the root is followed in height too (no ground).
    """

    pixels: np.ndarray
    depth: np.ndarray
    ground_y: float | None


def hips_index(names: Sequence[str] | None) -> int:
    """The joint to follow: the first named like hips/pelvis (Bandai's root sits on the floor), else joint 0."""
    matches = [j for j, n in enumerate(names or ()) if _HIPS_NAME.search(n)]
    return matches[0] if matches else 0


def project_clip(positions: np.ndarray, config: FigureConfig, follow_height: bool = False) -> ProjectedClip:
    """Follow the root (joint 0) in X/Z, project to the two panels, and fit one scale to the whole clip.

    follow_height: follow the root vertically too and draw no ground (a close-up of a limb)."""
    followed = np.array([1.0, 1.0 if follow_height else 0.0, 1.0])
    centred = positions - positions[:, :1] * followed  # (T, J, 3) root at X = Z = 0 (and Y = 0)
    x, y, z = centred[..., 0], centred[..., 1], centred[..., 2]  # each (T, J)
    horizontal = np.stack([x, z], axis=1)  # (T, 2, J): front shows X, side shows Z
    depth = np.stack([-z, x], axis=1)  # (T, 2, J): front camera at +Z, side camera at -X
    if follow_height:
        bottom, top = float(y.min()), float(y.max())
    else:
        bottom, top = min(0.0, float(y.min())), max(0.0, float(y.max()))
    half_width = max(float(np.abs(horizontal).max()), 1e-6)
    usable_h = config.panel_height - 2 * config.margin_px
    usable_half_w = config.panel_width / 2 - config.margin_px
    scale = min(usable_h / max(top - bottom, 1e-6), usable_half_w / half_width)  # pixels per unit
    panel_left = np.array([0.0, config.panel_width])[None, :, None]  # (1, 2, 1)
    floor_row = config.header_px + config.panel_height - config.margin_px
    px = panel_left + config.panel_width / 2 + horizontal * scale  # (T, 2, J)
    py = np.repeat(floor_row - (y[:, None, :] - bottom) * scale, 2, axis=1)  # (T, 2, J)
    ground_y = None if follow_height else floor_row + bottom * scale
    return ProjectedClip(np.stack([px, py], axis=-1), depth, ground_y)


class FigureDrawer:
    """Draws frame `t` of a projected clip as a palette image."""

    def __init__(self, parents: Sequence[int], sides: np.ndarray, config: FigureConfig, title: str = "") -> None:
        self.config = config
        self.title = title
        self.children = np.array([j for j, p in enumerate(parents) if p >= 0])
        self.parents = np.array([parents[j] for j in self.children])
        self.bone_colours = [SIDE_COLOURS[int(s)] for s in sides[self.children]]
        self.font = ImageFont.load_default()
        self.background = self._background()

    def _background(self) -> Image.Image:
        cfg = self.config
        image = Image.new("P", cfg.image_size, BACKGROUND)
        image.putpalette([c for rgb in PALETTE_RGB for c in rgb])
        draw = ImageDraw.Draw(image)
        draw.line([(cfg.panel_width, cfg.header_px), (cfg.panel_width, cfg.header_px + cfg.panel_height)], DIVIDER)
        draw.text((4, 3), self.title, fill=TEXT, font=self.font)
        for panel, name in enumerate(PANEL_NAMES):
            draw.text((panel * cfg.panel_width + 4, cfg.header_px + 2), name, fill=TEXT, font=self.font)
        return image

    def draw(self, clip: ProjectedClip, t: int, caption: str) -> Image.Image:
        cfg = self.config
        image = self.background.copy()
        draw = ImageDraw.Draw(image)
        for panel in range(len(PANEL_NAMES)):
            x0 = panel * cfg.panel_width + cfg.margin_px / 2
            if clip.ground_y is not None:
                draw.line([(x0, clip.ground_y), (x0 + cfg.panel_width - cfg.margin_px, clip.ground_y)], GROUND, 1)
            self._draw_panel(draw, clip.pixels[t, panel], clip.depth[t, panel])
        draw.text((4, cfg.header_px + cfg.panel_height + 3), caption, fill=TEXT, font=self.font)
        return image

    def _draw_panel(self, draw: ImageDraw.ImageDraw, points: np.ndarray, depth: np.ndarray) -> None:
        """points: (J, 2) pixels; depth: (J,). Far bones first so near limbs stay on top."""
        bone_depth = (depth[self.children] + depth[self.parents]) / 2  # (B,)
        radius = self.config.joint_radius_px
        for b in np.argsort(-bone_depth, kind="stable"):
            start, end = points[self.parents[b]], points[self.children[b]]
            draw.line([tuple(start), tuple(end)], self.bone_colours[b], self.config.bone_width_px)
        for j in np.argsort(-depth, kind="stable"):
            x, y = points[j]
            draw.ellipse([x - radius, y - radius, x + radius, y + radius], fill=JOINT)
