"""What runs live (numpy + onnxruntime, no torch): the model bundle and the ONNX sessions of the
denoiser, VQ decoder and motion-prompt encoder.
"""
