"""Audio in, live: sources (microphone, paced file, fast file), PortAudio
access, the ring buffer, device CLI.
"""
