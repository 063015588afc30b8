"""Benchmarks of the speech input: voice invariance of the gesture following (voices) and lip sync."""
