"""``generate --batch``: many audio files → motion files on a pool of worker processes or on Ray Data."""
