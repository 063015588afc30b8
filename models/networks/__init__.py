"""The generator's torch modules: causal convolutions and attention, quantizer, VQ-VAE, latent
denoiser, motion-prompt encoder (training and export only).
"""
