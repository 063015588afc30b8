"""Pictures: stick-figure GIF/MP4/PNG rendering (``gesturecast render``) and feature plots."""
