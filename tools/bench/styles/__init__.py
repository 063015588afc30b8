"""``gesturecast bench styles``: how visible the styles are (accuracy vs guidance, motion prompts, body parts)."""
