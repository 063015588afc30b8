"""Benchmarks of time: end-to-end latency (idle and under a competing load), its sweep over the latency settings,
and the frame scheduler."""
