"""The gesture runtime (numpy, no torch), the one home of a stream's gestures: words → speech acts and phrases →
cues → placement → imposition on the generator.

``director`` holds one stream's gestures (:class:`~gesturecast.realtime.gestures.director.GestureDirector`): every
door's words and gesture controls reach the cue plan through it. The lexicon's files are read and checked
(``lexicon``, ``lexicon_checks``; strokes located by ``strokes``) and encoded into the model's latent space as clips
(``clips``), once per session factory (``repertoire``). Words from transcripts (``transcripts``) and word controls
become cues through trigger phrases (``triggers``) or through the speech acts of phrases (``speech_acts``,
``phrases``); ``cues`` plans them, places the clips on the stream's latents and imposes them on the generator's
output, with ``reattach`` keeping the imposed limbs on the generated torso or hips. The lexicon is built offline
(``gesturecast.tools.gestures``), never imported here.
"""
