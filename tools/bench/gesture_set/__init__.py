"""The texts, spoken stories and kinematic detector of ``gesturecast bench gestures``."""
