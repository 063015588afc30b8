"""Training the generator (torch): presets, training arrays, feature augmentation, the VQ-VAE and
denoiser trainers, the full pipeline.
"""
