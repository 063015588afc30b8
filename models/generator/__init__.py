"""What the generator is, framework-free (numpy): denoiser config, diffusion math (schedules,
DDPM/DDIM, guidance), style vocabulary and text style embeddings. Read by training, export and the
runtime.
"""
