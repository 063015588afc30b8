"""Streaming speech features at the motion frame rate (the offline path is the same code): DSP,
normalisation, VAD, speaker norm, speech embedding.
"""
