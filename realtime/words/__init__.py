"""Words without times placed on their audio: forced alignment of known text, one sentence at a time, with a
fallback that never loses a sentence (:mod:`.aligner`, :mod:`.voicing`), a plain-text script placed over a whole
recording (:mod:`.script`), sentences placed as a live stream's audio arrives (:mod:`.live`), and the count of every
alignment's outcome (:mod:`.outcomes`)."""
