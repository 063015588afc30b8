"""Benchmarks of the voice-agent integrations (the Pipecat processor)."""
