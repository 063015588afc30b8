"""Voice-agent integrations (optional extras): gesturecast as a stage of someone else's speech pipeline."""
