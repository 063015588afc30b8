"""gesturecast: speech in, stylized full-body gestures out, live on a CPU.

The installed namespace maps the repository folders ``realtime/``, ``models/``, ``bridges/`` and
``tools/`` to ``gesturecast.realtime``, ``gesturecast.models``, ``gesturecast.bridges`` and
``gesturecast.tools``.
"""

__version__ = "0.1.0"
