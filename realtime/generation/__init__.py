"""The live generator side (numpy + onnxruntime, no torch): one latent frame per step, the style prompts it is
conditioned on, and the style mixture of one batched denoiser call.
"""
