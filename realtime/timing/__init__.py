"""Time: the injected monotonic clock, the latency budget and statistics,
the frame scheduler, the status line.
"""
