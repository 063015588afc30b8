"""Pictures of ``gesturecast bench styles`` (needs matplotlib: the eval/dev extra).

``OUT.png``: the confusion matrix at the guidance scale with the best mean style accuracy (rows: requested
style, columns: predicted label, row-normalised, annotated), mean style accuracy vs s with chance, and what
s does to the neutral style (beat consistency, FGD, jerk, acceleration, speed relative to the first s).
``OUT_parts.png``: per-part styles — each part's progress from the other prompt's single-style run toward its
own prompt's (1: as its own prompt moves a whole body) and the seam roughness at the border joints of the
single-style and per-part runs.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gesturecast.files import save_figure

DPI = 100
CELL_INCHES = 0.42
SIDE_INCHES = 5.5  # the two small panels' column
MIN_SHOWN_SHARE = 0.005  # cells below this stay unlabelled


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def best_guidance(report: dict) -> str:
    scored = {s: entry["style_accuracy"]["mean"] or 0.0 for s, entry in report["guidance"].items()}
    return max(scored, key=scored.get)


def _confusion(axis, entry: dict, scale: str) -> None:
    confusion = entry["confusion"]
    counts = np.asarray(confusion["counts"], float)  # (R, L)
    shares = counts / np.maximum(counts.sum(axis=1, keepdims=True), 1.0)
    axis.imshow(shares, cmap="Blues", vmin=0.0, vmax=1.0, aspect="auto")
    for (row, column), share in np.ndenumerate(shares):
        if share >= MIN_SHOWN_SHARE:
            axis.text(column, row, f"{share:.2f}".lstrip("0"), ha="center", va="center", fontsize=7,
                      color="white" if share > 0.6 else "black")
    axis.set_xticks(range(len(confusion["predicted"])), confusion["predicted"], rotation=60, ha="right", fontsize=8)
    axis.set_yticks(range(len(confusion["requested"])), confusion["requested"], fontsize=8)
    axis.set_xlabel("predicted by the style classifier")
    axis.set_ylabel("requested style")
    accuracy = entry["style_accuracy"]
    axis.set_title(f"s = {scale}: mean accuracy {accuracy['mean']:.2f} (chance {accuracy['chance']:.3f})")


def _accuracy_vs_guidance(axis, report: dict) -> None:
    scales = list(report["guidance"])
    values = [float(s) for s in scales]
    for style in report["styles"]:
        axis.plot(values, [report["guidance"][s]["style_accuracy"]["per_style"][style] or 0.0 for s in scales],
                  color="0.8", linewidth=0.8)
    axis.plot(values, [report["guidance"][s]["style_accuracy"]["mean"] or 0.0 for s in scales], "o-",
              color="tab:blue", label="mean over styles")
    axis.axhline(report["guidance"][scales[0]]["style_accuracy"]["chance"], color="tab:red", linestyle="--",
                 label="chance")
    axis.set_ylim(0.0, 1.0)
    axis.set_xlabel("guidance scale s")
    axis.set_ylabel("style accuracy")
    axis.set_title("style accuracy vs s (grey: each style)", fontsize=9)
    axis.legend(fontsize=8)


COST_METRICS = (("beat_consistency", "beat consistency"), ("fgd", "FGD"), ("jerk", "jerk"),
                ("acceleration", "acceleration"))


def _relative(values: list[float | None]) -> list[float]:
    """Values over the first one (NaN where missing)."""
    first = values[0]
    return [np.nan if v is None or not first else v / first for v in values]


def _cost_of_guidance(axis, report: dict) -> None:
    scales = list(report["guidance"])
    values = [float(s) for s in scales]
    metrics = [report["guidance"][s]["neutral_metrics"] for s in scales]
    for key, name in COST_METRICS:
        axis.plot(values, _relative([m[key] for m in metrics]), "o-", label=name)
    axis.plot(values, _relative([m["liveliness"]["speed_ratio"] for m in metrics]), "o-", label="joint speed")
    axis.axhline(1.0, color="0.5", linewidth=0.8)
    axis.set_xlabel("guidance scale s")
    axis.set_ylabel(f"relative to s = {scales[0]}")
    axis.set_title("what s costs the neutral style (held-out speech)", fontsize=9)
    axis.legend(fontsize=7)


def plot_guidance(report: dict, out_path: Path) -> Path:
    plt = _pyplot()
    scale = best_guidance(report)
    entry = report["guidance"][scale]
    rows, columns = np.asarray(entry["confusion"]["counts"]).shape
    width = max(6.0, CELL_INCHES * columns + 2.5)
    fig = plt.figure(figsize=(width + SIDE_INCHES, max(6.0, CELL_INCHES * rows + 2.5)), layout="constrained")
    grid = fig.add_gridspec(2, 2, width_ratios=(width, SIDE_INCHES - 1.0))
    _confusion(fig.add_subplot(grid[:, 0]), entry, scale)
    _accuracy_vs_guidance(fig.add_subplot(grid[0, 1]), report)
    _cost_of_guidance(fig.add_subplot(grid[1, 1]), report)
    speech = report["speech"]
    fig.suptitle(f"bench styles: {report['model']} — {speech['seconds']:.1f} s of {speech['clip']} per style and "
                 f"seed ({len(speech['seeds'])} seeds), {speech['sampler']}", fontsize=10)
    save_figure(fig, out_path, dpi=DPI)
    plt.close(fig)
    return out_path


def plot_parts(report: dict, out_path: Path) -> Path:
    plt = _pyplot()
    study = report["part_styles"]
    pairs = study["pairs"]
    fig, (progress_axis, seam_axis) = plt.subplots(1, 2, figsize=(13, 4.5), layout="constrained")
    parts = list(pairs[0]["signatures"])
    width = 0.8 / len(parts)
    for k, part in enumerate(parts):
        progress = [p["signatures"][part]["progress"] or 0.0 for p in pairs]
        progress_axis.bar(np.arange(len(pairs)) + (k - (len(parts) - 1) / 2) * width, progress, width, label=part)
    progress_axis.axhline(0.5, color="0.3", linestyle="--", linewidth=0.8)
    progress_axis.axhline(1.0, color="0.3", linestyle=":", linewidth=0.8)
    progress_axis.set_xticks(range(len(pairs)), [p["pair"] for p in pairs], fontsize=8)
    progress_axis.set_ylabel("progress toward its own prompt (1: as on a whole body)")
    progress_axis.legend(title="part", fontsize=8)
    progress_axis.set_title(f"part signatures at s = {study['guidance']:g}")
    kinds = [("single-style runs", lambda p: p["seams"]["single_style_border_mean"]),
             ("per-part run", lambda p: p["seams"]["per_part"]["border"])]
    width = 0.8 / len(kinds)
    for k, (name, value) in enumerate(kinds):
        seam_axis.bar(np.arange(len(pairs)) + (k - (len(kinds) - 1) / 2) * width, [value(p) for p in pairs], width,
                      label=name)
    seam_axis.set_xticks(range(len(pairs)), [p["pair"] for p in pairs], fontsize=8)
    seam_axis.set_ylabel("border-joint angular acceleration (°/frame²)")
    seam_axis.legend(fontsize=8)
    seam_axis.set_title("seams: border joints (shoulders, spine)")
    save_figure(fig, out_path, dpi=DPI)
    plt.close(fig)
    return out_path


def plot_style_study(report: dict, out_path: Path) -> list[Path]:
    """Both pictures: ``out_path`` and ``<stem>_parts<suffix>`` beside it."""
    parts_path = out_path.with_name(f"{out_path.stem}_parts{out_path.suffix}")
    return [plot_guidance(report, out_path), plot_parts(report, parts_path)]
