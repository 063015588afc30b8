"""gesturecast: speech in, stylized full-body gestures out, live on a CPU.

The library (the Python API page of the documentation: docs/python-api.md in the source repository)::

    import gesturecast
    motion = gesturecast.generate("talk.wav", style="happy")   # -> gesturecast.Motion
    motion.save("talk.bvh")

    with gesturecast.Stream(gesturecast.Settings(style="old"), outputs=gesturecast.Outputs(vmc="127.0.0.1")) as s:
        frames = s.push(samples, sample_rate=48000)   # at once, before they are due
    # each frame at its presentation time: Stream(on_frame=...), ``for f in s.frames()``, ``async for f in s.aframes()``

The names below are imported on first use, so ``import gesturecast`` stays light (no model, no onnxruntime).
The installed namespace maps the repository folders ``realtime/``, ``models/``, ``bridges/`` and ``tools/`` to
``gesturecast.realtime``, ``gesturecast.models``, ``gesturecast.bridges`` and ``gesturecast.tools``.
"""

from __future__ import annotations

import importlib

__version__ = "0.2.0"

# public name -> the module that defines it
_EXPORTS = {
    "generate": "gesturecast.api",
    "Motion": "gesturecast.api",
    "Stream": "gesturecast.realtime.run.stream",
    "Settings": "gesturecast.settings",
    "Outputs": "gesturecast.bridges.output_settings",
    "PoseFrame": "gesturecast.frames",
    "UserError": "gesturecast.errors",
}
__all__ = [*_EXPORTS, "__version__"]


def __getattr__(name: str) -> object:
    if name not in _EXPORTS:
        raise AttributeError(f"module 'gesturecast' has no attribute {name!r}")
    return getattr(importlib.import_module(_EXPORTS[name]), name)


def __dir__() -> list[str]:
    return sorted(__all__)
