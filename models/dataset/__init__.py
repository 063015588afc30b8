"""The training-set cache: dataset layouts on disk, building and reading the cache, frame-aligned audio
and pair augmentation (numpy).
"""
