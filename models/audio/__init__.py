"""Audio representation (numpy): audio files to 16 kHz mono float32, and streaming speech features at the motion
frame rate (the offline path is the same code): DSP, normalisation, VAD, speaker norm, speech embedding, visemes.
"""
