"""The evaluation's outputs: deltas between systems, the printed table, plots and the JSON file."""

from __future__ import annotations

import json
import math
import subprocess
from pathlib import Path

from gesturecast.files import save_figure, write_text_atomic
from gesturecast.tools.eval.suite import DDIM_STEPS, DDPM

REPO_ROOT = Path(__file__).resolve().parents[2]
# (column title, path into a system's result, format)
TABLE_COLUMNS = (
    ("BC", ("beat_consistency",), "{:.3f}"),
    ("FGD", ("fgd",), "{:.2f}"),
    ("L1div", ("diversity", "l1"), "{:.2f}"),
    ("seed div", ("diversity", "seed"), "{:.3f}"),
    ("jerk", ("jerk",), "{:.1f}"),
    ("accel", ("acceleration",), "{:.2f}"),
    ("speed×", ("liveliness", "speed_ratio"), "{:.2f}"),
    ("var×", ("liveliness", "variance_ratio"), "{:.2f}"),
    ("style acc", ("style_accuracy", "mean"), "{:.2f}"),
)
DELTA_METRICS = tuple((title, path) for title, path, _ in TABLE_COLUMNS)


def git_commit() -> dict:
    """The repository's HEAD commit and whether the working tree has uncommitted changes."""
    def git(*args: str) -> str:
        return subprocess.run(["git", *args], cwd=REPO_ROOT, capture_output=True, text=True, check=False).stdout
    commit = git("rev-parse", "HEAD").strip() or None
    return {"commit": commit, "dirty": bool(git("status", "--porcelain", "--untracked-files=no").strip())}


def lookup(result: dict, path: tuple[str, ...]) -> float | None:
    value = result
    for key in path:
        value = value.get(key) if isinstance(value, dict) else None
    return value if isinstance(value, int | float) and math.isfinite(value) else None


def difference(a: dict, b: dict) -> dict:
    """Per metric a − b (None where either is missing)."""
    out = {}
    for title, path in DELTA_METRICS:
        x, y = lookup(a, path), lookup(b, path)
        out[title] = None if x is None or y is None else x - y
    return out


def ddim_vs_ddpm(systems: dict) -> dict:
    if DDPM not in systems:
        return {}
    return {name: difference(result, systems[DDPM]) for name, result in systems.items() if name.startswith("ddim_k")}


def format_table(systems: dict) -> str:
    """A Markdown table: one row per system (held-out set), the columns of :data:`TABLE_COLUMNS`."""
    header = "| system | " + " | ".join(title for title, _, _ in TABLE_COLUMNS) + " |"
    lines = [header, "|" + " --- |" * (len(TABLE_COLUMNS) + 1)]
    for name, result in systems.items():
        cells = [fmt.format(v) if (v := lookup(result, path)) is not None else "–" for _, path, fmt in TABLE_COLUMNS]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def plot_curves(systems: dict, lookahead: dict, out_prefix: Path) -> list[Path]:
    """metric vs K (DDPM and ground truth as lines) and, with look-ahead models, metric vs δa."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    written = []
    ks = [k for k in DDIM_STEPS if f"ddim_k{k}" in systems]
    curves = [("vs_k", "DDIM steps K", ks, [systems[f"ddim_k{k}"] for k in ks], True)]
    if lookahead:
        deltas = sorted(lookahead, key=int)
        curves.append(("vs_lookahead", "audio look-ahead δa (frames)", [int(d) for d in deltas],
                       [lookahead[d] for d in deltas], False))
    for suffix, xlabel, xs, results, with_references in curves:
        if not xs:
            continue
        figure, axes = plt.subplots(2, 4, figsize=(16, 7))
        for axis, (title, path, _) in zip(axes.flat, [c for c in TABLE_COLUMNS if c[0] != "seed div"], strict=False):
            axis.plot(xs, [lookup(r, path) if lookup(r, path) is not None else math.nan for r in results], "o-")
            for name, style in (("ground_truth", "g--"), (DDPM, "r:")) if with_references else ():
                if name in systems and lookup(systems[name], path) is not None:
                    axis.axhline(lookup(systems[name], path), color=style[0], linestyle=style[1:], label=name)
            axis.set(title=title, xlabel=xlabel, xticks=xs)
            axis.legend(fontsize="small") if axis.get_legend_handles_labels()[0] else None
        figure.tight_layout()
        path = out_prefix.with_name(f"{out_prefix.stem}_{suffix}.png")
        save_figure(figure, path, dpi=80)
        plt.close(figure)
        written.append(path)
    return written


def write_json(report: dict, path: Path) -> Path:
    write_text_atomic(path, json.dumps(report, indent=1) + "\n")
    return path
