"""The Pipecat processor, under a short name (docs/pipecat.md; ``pip install 'gesturecast[pipecat]'``)::

    from gesturecast.pipecat import GesturecastProcessor, GestureStyleFrame

Without Pipecat installed the import fails with one line naming the extra to install.
"""

from __future__ import annotations

from gesturecast.extras import missing_extra

try:
    from gesturecast.realtime.agents.pipecat_processor import GesturecastProcessor, GestureStyleFrame
except ModuleNotFoundError as error:
    message = missing_extra(error)
    if message is None:
        raise
    raise ModuleNotFoundError(message, name=error.name) from None

__all__ = ["GestureStyleFrame", "GesturecastProcessor"]
