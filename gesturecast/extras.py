"""Optional dependencies: which extra brings a missing module, said in one line.

The live runtime needs none of them; training and export need torch (the ``train`` extra), the Pipecat processor
needs Pipecat (``pipecat``), ``--ray`` needs Ray (``scale``), plots need matplotlib (``eval``).
"""

from __future__ import annotations

TORCH_INSTALL = "pip install torch==2.13.0 && pip install 'gesturecast[train]'"  # the CPU build first (README)

# top-level module -> (what it is, how to install it)
EXTRAS: dict[str, tuple[str, str]] = {
    "torch": ("torch", TORCH_INSTALL),
    "onnx": ("onnx", TORCH_INSTALL),
    "pipecat": ("Pipecat", "pip install 'gesturecast[pipecat]'"),
    "ray": ("Ray", "pip install 'gesturecast[scale]'"),
    "matplotlib": ("matplotlib", "pip install 'gesturecast[eval]'"),
    "librosa": ("librosa", "pip install 'gesturecast[eval]'"),
}


def missing_extra(error: ModuleNotFoundError) -> str | None:
    """One line naming the extra that brings the missing module, or None when no extra brings it."""
    top = (error.name or "").partition(".")[0]
    if top not in EXTRAS:
        return None
    what, install = EXTRAS[top]
    return f"{what} is not installed; this needs it: {install}"
