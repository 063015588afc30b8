"""Time: the injected monotonic clock, pose frames with timestamps, the latency budget and statistics,
the frame scheduler, the status line.
"""
