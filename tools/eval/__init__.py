"""``gesturecast eval`` and ``gesturecast eval-train``: the objective evaluation suite and its report."""
