"""The gesture runtime (numpy, no torch): words → speech acts and phrases → cues → placement → imposition on the
generator.

The lexicon's files are read and checked (``lexicon``, ``lexicon_checks``; strokes located by ``strokes``) and
encoded into the model's latent space as clips (``clips``). Words from transcripts and word controls (``words``)
become cues directly through trigger words, or through the speech acts of phrases (``speech_acts``,
``phrases``); ``cues`` plans them, places the clips on the stream's latents and imposes them on the generator's
output, with ``reattach`` keeping the imposed limbs on the generated torso or hips. The lexicon is built offline
(``gesturecast.tools.gestures``), never imported here.
"""
