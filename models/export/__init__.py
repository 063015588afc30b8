"""Trained torch networks -> ONNX graphs and model bundles (torch)."""
