"""``gesturecast serve``: many concurrent streams over WebSocket with one batched denoiser session."""
