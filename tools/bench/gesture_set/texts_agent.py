"""A voice agent's replies for ``gesturecast bench pipecat``: written before the sentence path of the Pipecat
processor or the aligner was tuned, and never used to write rules, phrases or to train the classifier.

The conventions are those of :mod:`gesturecast.tools.bench.gesture_set.texts` (``[mark]`` before the word that opens
an intended speech act). The phrasings are the everyday ones an assistant says (a receptionist robot, a museum guide,
a game host, a support bot), so that a reply's cues are decided as they are with exact word times: what this set
measures is whether they still land on their words when a TTS service gives only the sentence's text, before or
after its audio. Each reply also has ordinary sentences (directions, facts, small talk) where nothing should play.
Twelve replies, 24 intended cues (greeting 5, thanks 5, farewell 5, celebration 4, presenting 3, calling 2).
"""

from __future__ import annotations

AGENT_REPLIES: dict[str, tuple[str, ...]] = {
    "reception-robot": (
        "[wave]Hello everyone, and welcome to the Harbour Hotel.",
        "Check-in opens at three o'clock, and breakfast is served on the second floor.",
    ),
    "museum-guide": (
        "[wave]Hi there, I'm your guide for the dinosaur hall.",
        "[guide]Over here you can see the skull of a young tyrannosaur.",
        "It was found in Montana in nineteen ninety.",
    ),
    "lost-luggage": (
        "[bow]Thank you so much for waiting.",
        "Your suitcase was put on the wrong flight, and it will arrive tomorrow morning.",
        "[bye]Goodbye, and see you tomorrow!",
    ),
    "quiz-host": (
        "That answer is correct.",
        "[raise-both]Hooray, you did it, you won the final round!",
        "[bow]Thanks for playing with us tonight.",
    ),
    "support-bot": (
        "[wave]Good morning, how can I help you today?",
        "Your router restarts every night at two, which clears the connection.",
        "[bow]Thank you for your patience.",
        "[bye]Have a great day!",
    ),
    "tour-bus": (
        "[call]Come on over, everyone, the bus is about to leave.",
        "We will stop at the old lighthouse for twenty minutes.",
        "[guide]This is the bridge the town was named after.",
    ),
    "game-companion": (
        "[raise-both]Yes! We finally beat the dragon!",
        "The next quest starts in the northern forest, past the mill.",
        "[bye]See you next time, adventurer.",
    ),
    "school-robot": (
        "[wave]Hello class, it is nice to meet you all.",
        "Today we will learn how plants drink water through their roots.",
        "[call]Come closer so you can see the leaves.",
    ),
    "restaurant-host": (
        "Your table by the window is almost ready.",
        "[guide]Here is the menu for this evening.",
        "[bow]Thank you for choosing us tonight.",
    ),
    "sports-coach": (
        "[wave]Hey team, great to see you all here.",
        "Three more laps and the session is over.",
        "[raise-both]Congratulations, that is a new personal best!",
    ),
    "library-assistant": (
        "[raise-both]Hooray, the book you reserved is back on the shelf!",
        "It is due again in three weeks, and you can renew it online.",
        "[bye]Bye for now, and happy reading.",
    ),
    "radio-host": (
        "It is twenty past eight, and the traffic on the ring road is moving slowly.",
        "[bow]Many thanks to everyone who called in this morning.",
        "[bye]Take care, and goodbye from all of us.",
    ),
}
