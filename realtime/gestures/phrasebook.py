"""The phrasebook: for each speech act, the phrases of everyday English that can open it, and where each may stand.

The phrases come in families of general English, not from any benchmark text:

- **greeting**: hello / hi / hey and their "there" forms, the informal "hiya", "howdy", "g'day", "yo"; the times of
  day with "good" ("good morning") and bare ("Morning, all"); "greetings"; "welcome" (its "aboard / back / in" is
  read by the classifier from the words after it).
- **thanks**: "thank you" / "thanks" and their intensified forms ("thanks a lot / a million / ever so much", "thank
  you all"), "many thanks", "a big thank you", "much appreciated", "much obliged", "I really appreciate", the
  British "cheers" and "ta".
- **farewell**: "bye" and "goodbye" forms, "see you / ya", the nights ("goodnight", "night night", "sleep well",
  "sweet dreams"), the wishes
  ("have a nice day", "safe travels / trip / journey", "take care", "take it easy"), the leave-takings ("catch you
  later", "so long", "until / till next time", "peace out", "later", "cheerio").
- **celebration**: the cheers ("hooray", "hip hip hooray", "woohoo", "woo", "yay", "yippee"), the praise ("well
  done", "bravo", "congratulations", "nailed it", "let's go", "yes!") and the evaluative interjections ("brilliant",
  "fantastic", "amazing", "awesome", "excellent", "superb", "terrific", "marvellous").
- **presenting**: the deictic phrases ("this is", "here is", "over there", "look at", "take a look"), the
  introductions ("meet", "let me introduce", "allow me to introduce", "may I present", "let me show you"), the
  display phrases ("here we have", "over here is", "feast your eyes on", "behold", "check this out") and the
  directions ("on your left").
- **calling**: "come here / over / on / along / closer / forward / up", "come join us", "gather round", "step
  forward", "over here", "this way".

Many of these words are ordinary narration as often ("Morning traffic was light", "a brilliant idea", "Later, the
rook reaches the seventh rank", "Yes, the figures are in", "let's go home", "in this way", "come up with a plan", "a
sight to behold"). So each phrase may also say where it can be an act (:func:`placement`, read by the rules of
:mod:`gesturecast.realtime.gestures.speech_acts`):

- :data:`ALONE`: only standing alone at the start of a clause ("Brilliant!", "Morning, all.", "Let's go, team!"),
  with punctuation after it or before an addressee that a punctuation mark closes (:data:`ADDRESSEES`: "Morning
  all," but not "Later all the guests left"); anywhere else it is no act.
- :data:`EXCLAIMED`: as :data:`ALONE`, but punctuation is not enough: an exclamation mark or an addressee ("Yes!",
  "Later, guys"; "Yes, the figures are in" and "Later, the rook …" are no act).
- :data:`OPENING`: only opening a clause ("Goodnight, everyone", "Come up, all of you", "Behold the cake"; "a
  goodnight kiss", "the topic may come up", "a sight to behold" are none); the classifier decides there.
- :data:`WHOLE`: phrases no narration uses as anything else: opening a clause they are their act ("Hip hip hooray for
  the couple", "Thanks ever so much for your help", "Allow me to introduce the best man"), unless a rule for
  reported, quoted or named words rules them out.
"""

from __future__ import annotations

TIMES_OF_DAY = ("morning", "afternoon", "evening")
GOOD_TIMES = tuple(f"good {time}" for time in TIMES_OF_DAY)
WISHES = ("nice", "good", "great", "lovely", "wonderful", "pleasant", "safe", "fantastic")  # "have a nice day"
WISHED = ("day", "evening", "afternoon", "morning", "night", "weekend", "week", "trip", "journey", "flight",
          "holiday", "time")
FAREWELL_WISHES = tuple(f"have a {adjective} {time}" for adjective in WISHES for time in WISHED)
INTENSIFIED_THANKS = tuple(f"{thanks} {more}" for thanks in ("thanks", "thank you")
                           for more in ("a lot", "a million", "ever so much", "so much", "very much", "a bunch"))
EVALUATIVE = ("brilliant", "fantastic", "amazing", "awesome", "excellent", "superb", "terrific", "marvellous")

PHRASEBOOK: dict[str, tuple[str, ...]] = {  # intent -> phrases (normalised tokens) that can open it
    "greeting": ("hello", "hi", "hey", "hiya", "howdy", "g'day", "yo", "hello there", "hi there", "hey there",
                 *GOOD_TIMES, *TIMES_OF_DAY, "good day", "greetings", "welcome"),
    "thanks": ("thank you", "thanks", "thank", "many thanks", "much appreciated", "cheers", "thank you very much",
               *INTENSIFIED_THANKS, "thank you all", "thanks all", "thanks everyone", "a big thank you",
               "big thanks", "much obliged", "i really appreciate", "ta", "ta very much"),
    "farewell": ("bye", "goodbye", "good bye", "bye bye", "see you", "see ya", "farewell", "take care", "so long",
                 "good night", "goodnight", "night night", "nighty night", "sleep well", "sleep tight",
                 "sweet dreams", *FAREWELL_WISHES, "catch you later",
                 "enjoy the rest of your day", "enjoy the rest of your evening", "enjoy your evening",
                 "enjoy your weekend", "safe travels", "safe trip", "safe journey", "until next time",
                 "till next time", "talk soon", "take it easy", "peace out", "later", "cheerio"),
    "celebration": ("hooray", "hurray", "hurrah", "hip hip hooray", "yay", "woohoo", "woo hoo", "woo", "yippee",
                    "congratulations", "congrats", "well done", "bravo", "nailed it", "let's go", "yes",
                    *EVALUATIVE),
    "presenting": ("here is", "here are", "here's", "here you can see", "here we have", "this is", "these are",
                   "this is our", "these are our", "this is my", "look at", "take a look", "have a look", "over there",
                   "check out", "check this out", "meet", "let me show you", "let me introduce",
                   "allow me to introduce", "may i introduce", "may i present", "over here is", "over here we have",
                   "feast your eyes on", "behold", "on your left", "on your right", "to your left", "to your right"),
    "calling": ("come on", "come here", "come over", "come over here", "come closer", "over here", "gather round",
                "gather around", "come along", "come on over", "come forward", "come on up", "come up here",
                "come up", "come join us", "step forward", "this way"),
}

ALONE = frozenset([*TIMES_OF_DAY, "good day", *EVALUATIVE, "woo", "nailed it", "let's go", "this way", "ta",
                   "cheerio"])
EXCLAIMED = frozenset(["yes", "later"])
OPENING = frozenset(["goodnight", "sleep well", "sleep tight", "sweet dreams", "come up", "behold"])
WHOLE = frozenset(["hiya", "howdy", "g'day", "yo", "hip hip hooray", *INTENSIFIED_THANKS, "thank you all",
                   "a big thank you", "big thanks", "much obliged", "ta very much", "night night", "nighty night",
                   "safe travels", "safe trip", "safe journey", "peace out", "catch you later", "until next time",
                   "till next time", "allow me to introduce", "may i present", "may i introduce", "over here is",
                   "over here we have", "feast your eyes on", "check this out", "gather round", "gather around",
                   "come over here"])
ADDRESSEES = frozenset(["everyone", "everybody", "all", "folks", "guys", "y'all", "team", "friends", "gang",
                        "people", "class", "kids", "mate", "mates", "pal", "love", "darling", "sir", "madam",
                        "ma'am", "chaps", "lads", "ladies", "gentlemen", "boys", "girls",
                        "please"])  # "Morning, all.", "This way, please", "Brilliant, guys!": closing a clause
NOT_AFTER = {"come up": frozenset(["with", "against", "short", "again"])}  # "come up with a plan": no call


def placement(phrase: str) -> str | None:
    """Where ``phrase`` can be its act: "alone", "exclaimed", "opening", "whole" (the module docstring), or None
    (anywhere: the rules and the classifier decide)."""
    for name, phrases in (("alone", ALONE), ("exclaimed", EXCLAIMED), ("opening", OPENING), ("whole", WHOLE)):
        if phrase in phrases:
            return name
    return None


def spoken(phrase: str) -> str:
    """A phrasebook phrase as a sentence opens with it ("may i present" → "May I present")."""
    words = ["I" if word == "i" else word for word in phrase.split()]
    return " ".join(words)[0].upper() + " ".join(words)[1:]
