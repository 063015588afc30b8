"""Audio in: files to 16 kHz mono float32, sources (microphone, paced file, fast file), PortAudio
access, the ring buffer, device CLI.
"""
