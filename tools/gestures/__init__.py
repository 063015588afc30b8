"""Building the gesture runtime's data offline (numpy): the lexicon from the Bandai takes and the speech-act
classifier from its training sentences; ``gesturecast gestures`` runs them.
"""
