"""The gesture lexicon as the runtime reads it: the shipped one (``models/weights/gestures``), another built one, or
a folder of the user's own clips with ``gestures.json`` (``--gestures DIR``; docs/gestures.md).

The reader lives beside the rules that build the lexicon (:mod:`gesturecast.models.dataset.gesture_lexicon`,
numpy and json only; a user's BVH clips are retargeted by the same code as the training data). This module is the
runtime's name for it.
"""

from __future__ import annotations

from gesturecast.models.dataset.gesture_lexicon import (
    DEFAULT_STYLE,
    GestureEntry,
    GestureVariant,
    Lexicon,
    default_lexicon_dir,
    load_lexicon,
    read_built_lexicon,
    read_user_lexicon,
)

__all__ = ["DEFAULT_STYLE", "GestureEntry", "GestureVariant", "Lexicon", "default_lexicon_dir", "load_lexicon",
           "read_built_lexicon", "read_user_lexicon"]
