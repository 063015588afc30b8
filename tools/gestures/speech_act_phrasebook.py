"""Training sentences for every phrase of the phrasebook (:mod:`gesturecast.realtime.gestures.phrasebook`): each
phrase used as its act, and the same words in ordinary narration (the phrasebook revision).

:func:`phrasebook_acts` opens a sentence with each phrase, marked with its act's gesture, before a continuation that
suits the act ("[bow]Much obliged for the lift home."); :func:`phrasebook_ordinary` gives the ordinary uses of the
same words ("Morning traffic was light", "a brilliant idea", "a goodnight kiss", "Later, the council changed its
mind", "come up with a plan"). The rules decide many of these phrases by where they stand, and the classifier learns
from the rest (a sentence's candidates that no rule decides), so both kinds also check the rules. Seeded; none of it
is taken from the benchmark's texts.
"""

from __future__ import annotations

import random

from gesturecast.realtime.gestures.phrasebook import PHRASEBOOK, spoken

GESTURE_OF = {"greeting": "wave", "thanks": "bow", "farewell": "bye", "celebration": "raise-both",
              "presenting": "guide", "calling": "call"}
TAILS = {  # intent -> continuations after a phrase; "{a}": an addressee
    "greeting": ("{a}, lovely to see you.", "{a}!", "{a}, how was the drive?", "{a}, grab a seat.",
                 "{a}, are we all here?", "and nice to meet you."),
    "thanks": ("for the lift home.", "{a}, that was kind.", "for sorting it out so fast.", "for everything, {a}.",
               "for the birthday card.", "{a}, I owe you one."),
    "farewell": ("{a}!", "and drive carefully.", "{a}, speak soon.", "and mind the ice on the steps.",
                 "everyone, it was fun.", "{a}, sleep tight."),
    "celebration": ("we won the quiz!", "{a}, you passed!", "the car started first time!", "that's a new record!",
                    "the funding came through!", "{a}, what a finish!"),
    "presenting": ("the new delivery van.", "our finished mural.", "the puppy we adopted.", "the cake I baked.",
                   "my grandad's old radio.", "the plans for the extension.", "Doctor Evans, our new vet.",
                   "Mrs Okoro, who runs the choir.", "my neighbour Tom, the best baker on the street."),
    "calling": ("{a}, the show is starting.", "{a}, there's room at the front.", "and bring your drinks.",
                "{a}, I saved you a seat.", "everyone, it's photo time.", "and have a go yourself."),
}
VERB_TAILS = ("it, {a}.", "all your help.", "everything you did for us.")  # "I really appreciate …"
JOINED = frozenset(["for", "and", "it,", "all", "everything"])  # continuations that follow without a comma
ADDRESSEES = ("everyone", "folks", "Sam", "team", "all", "Nadia", "love", "guys", "class", "Mister Patel")
ORDINARY = (  # the phrasebook's words in narration: none of them opens a gesture
    "Morning traffic was light on the ring road.", "The evening news ran twenty minutes over.",
    "Afternoon tea is served in the library at four.", "It was a good day for the farmers.",
    "Evening classes start again in September.", "The morning after the storm was bright and still.",
    "She gave him a goodnight kiss and turned off the lamp.", "The goodnight story took longer than the bath.",
    "Later that week the river froze solid.", "Later, the council changed its mind about the car park.",
    "Yes, the figures are in, and they are poor.", "Yes or no questions are easier to count.",
    "It was a brilliant idea that nobody ever tried.", "Brilliant sunshine lit the hills all afternoon.",
    "The reviews were fantastic, but the tickets did not sell.", "An amazing number of swallows stayed the winter.",
    "The soup was excellent and the bread was stale.", "Terrific winds tore the roof off the barn.",
    "Let's go over the numbers once more, the manager told the board.", "The children never say let's go home.",
    "The topic may come up again at the next meeting.", "Come up with a better plan and we will listen.",
    "In this way the dough stays soft for days.", "This way of working suits small teams.",
    "The old castle was a sight to behold.", "Peace out was scrawled on the locker door.",
    "The candidates woo the voters with promises.", "He nailed it to the door of the shed.",
    "Take it easy on the brakes when the road is wet.", "So long as the pumps work, the mine stays dry.",
    "Night night was the last thing the parrot learned.", "Yo-yo prices make planning hard for shops.",
    "The catch you later attitude of the staff annoyed the customers.", "The airline wished everyone safe travels.",
    "He was much obliged to his uncle for the loan.", "I really appreciate how quiet the town is in winter.",
    "The charity sent a big thank you card to every school.", "Ta-da, the magician said, and the dove was gone.",
    "Over here is colder than over there, the locals say.", "Behold was an old word for look.",
    "The woo of the owls kept us awake.", "Hip hip hooray was the headline on the back page.",
    "Cheerio was printed on the side of the box.", "Come up short again and the coach will drop you.",
)


def _fill(text: str, rng: random.Random) -> str:
    return text.replace("{a}", rng.choice(ADDRESSEES))


def phrasebook_acts(rng: random.Random, per_phrase: int = 2) -> list[str]:
    """``per_phrase`` sentences per phrasebook phrase (the "have a … day" wishes once), each opening with the
    phrase as its act."""
    sentences = []
    for intent, phrases in PHRASEBOOK.items():
        for phrase in phrases:
            count = 1 if phrase.startswith("have a ") else per_phrase
            for _ in range(count):
                tail = rng.choice(VERB_TAILS if phrase.endswith("appreciate") else TAILS[intent])
                if phrase.split()[-1] in ("our", "my"):  # "this is our" + "the new van" → "this is our new van"
                    tail = tail.split(" ", 1)[1]
                joiner = " " if intent == "presenting" or tail.split()[0] in JOINED else ", "
                sentences.append(f"[{GESTURE_OF[intent]}]{spoken(phrase)}{joiner}{_fill(tail, rng)}")
    return sentences


def phrasebook_ordinary(copies: int = 3) -> list[str]:
    """Every :data:`ORDINARY` sentence ``copies`` times (as many examples as a phrase's acts)."""
    return [sentence for sentence in ORDINARY for _ in range(copies)]
