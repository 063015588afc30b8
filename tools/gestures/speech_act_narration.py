"""Generated narration for the speech-act classifier: the candidate phrases in ordinary use, none of them an act.

Hand-written "none" sentences (:data:`gesturecast.tools.gestures.speech_act_data.NOT_ACTS`) are few; a classifier
trained on them learns their wording. Here templates combine subjects, nouns and continuations into the ways narration
uses the same words: "this is" / "these are" / "here is" opening a point, a period or a pattern rather than a thing
in the room; "over there" placing a story far away; "welcome" as an adjective; "look at the figures and …" as a
condition; "see you" and "come on" inside a longer verb phrase; greetings and thanks as nouns; "have a nice day",
"good night" and "so long" inside a sentence; "meet the deadline". To keep presenting apart from them, the same
openers are also generated before things that are there to see (:func:`presenting_sentences`). Seeded: the same
sentences on every run. None of it is taken from the benchmark's texts.
"""

from __future__ import annotations

import random

ABSTRACT = ("pattern", "habit", "mistake", "trend", "rule", "lesson", "example", "case", "argument", "idea", "claim",
            "risk", "myth", "period", "decade", "generation", "stage", "step", "phase", "difference", "debate",
            "theory", "tradition", "custom", "point", "puzzle", "paradox", "question", "choice", "compromise", "twist",
            "fact", "theme", "tension", "shift", "turning point", "weakness", "strength", "promise", "part", "kind",
            "sort", "side", "beginning", "heart", "root", "essence", "cause", "result", "outcome", "effect",
            "consequence", "price", "method", "approach", "story", "account", "version", "reading", "sense",
            "feeling", "mood", "moment", "era", "century", "season", "chapter", "episode", "problem", "detail",
            "aspect", "reason", "danger", "irony", "secret", "trick", "catch", "problem with the plan", "truth",
            "surprise", "summary", "conclusion", "principle", "habit of the age", "change", "decision", "failure",
            "success", "crisis", "opportunity", "challenge", "struggle", "attitude", "belief", "tone", "style")
QUALITIES = ("", "common ", "familiar ", "typical ", "rare ", "serious ", "simple ", "strange ", "small ", "recurring ",
             "modern ", "old ", "useful ", "painful ", "curious ")
ORDINALS = ("first", "second", "third", "last", "only", "oldest", "earliest", "latest", "hardest", "clearest")
POINT_TAILS = ("that repeats across the region.", "that few people expected.", "we will come back to later.",
               "in the history of the valley.", "for anyone who studies it.", "of the whole period.",
               "worth remembering.", "that shaped the century.", "in most accounts of the war.",
               "that economists like to point out.", "and it explains a lot.", "seen in many families.",
               "behind most of the arguments.", "that the critics missed.", "from the early years of the firm.",
               "nobody could agree on.", "of which the author is proudest.", "in the second half of the book.")
PEOPLE = ("the locals", "people", "farmers", "children", "the monks", "fishermen", "most families", "the clerks",
          "the older women", "shopkeepers", "the settlers", "the miners", "students", "the priests")
DOINGS = ("still speak the old dialect.", "used to keep goats.", "grow rice on steep terraces.",
          "work until dark in summer.", "close their shops at noon.", "drink tea with salt.",
          "had never seen a car.", "marry young.", "build their houses from stone.", "eat late in the evening.",
          "vote for the same party every time.", "walk for hours to reach the market.")
WELCOMED = ("relief", "change", "break", "surprise", "sight", "boost", "distraction", "addition", "rest", "breeze",
            "reminder", "rain", "shade", "pause", "development", "gesture")
WELCOME_VERBS = ("came at the end of a long week.", "arrived in the spring.", "followed the long winter.",
                 "reached the village at last.", "changed the mood of the meeting.", "lifted the whole team.")
WELCOME_FOR = ("for the tired crew.", "after months of drought.", "for the small shops in town.",
               "in a difficult year.", "for the players after the long trip.", "that nobody had planned.")
EVIDENCE = ("the numbers", "the figures", "the record", "the evidence", "the history", "the data", "the census",
            "the timeline", "the old accounts", "the letters", "the prices", "the maps of the period")
CONSEQUENCES = ("the pattern is obvious.", "a different story appears.", "the decline starts earlier.",
                "you see the same gap.", "nothing adds up.", "the town's growth makes sense.",
                "the answer is clear.", "the myth falls apart.")
SEERS = ("The neighbours", "Nobody", "Your teacher", "The guards", "People on the bus", "Anyone in the street",
         "The camera", "Your parents", "The whole class", "Drivers")
SEEING = ("could see you from the road.", "will see you if you stand there.", "can see you are worried.",
          "would see you coming a mile away.", "saw you leaving the shop.", "might see you on the news.",
          "can see you through the window.", "will see you in a new light.")
DEVICES = ("The lights", "The heating", "The alarm", "The radio", "The sprinklers", "The music", "The engine",
           "The fans", "The street lamps", "The screens", "The pumps", "The kettle")
SWITCHING = ("would come on at dusk.", "came on by itself.", "will come on when the door opens.",
             "used to come on every morning at six.", "came on halfway through the film.",
             "did not come on until noon.", "should come on as soon as the power returns.",
             "came on with a loud click.")
OWNERS = ("Their", "Her", "His", "Our", "A", "The", "My")
MANNERS = ("quick", "long", "brief", "final", "tearful", "warm", "polite", "awkward", "cheerful", "formal")
ACT_NOUNS = ("hello", "goodbye", "farewell", "thanks", "welcome", "greetings", "goodbyes", "hellos")
NOUN_TAILS = ("took most of the evening.", "turned into a long chat.", "was printed in the newsletter.",
              "made everyone smile.", "lasted longer than the visit.", "was lost in the noise.",
              "went unnoticed.", "surprised the whole family.")
PLANNERS = ("They", "We", "The tourists", "My parents", "The children", "Most visitors", "The class", "Our guests")
PLANS = ("wanted to have a nice day", "hoped to have a good weekend", "did not have a great time",
         "planned to have a lovely evening", "tried to have a good night", "expected to have a pleasant trip")
PLAN_TAILS = ("at the lake.", "despite the rain.", "in the city.", "with their cousins.", "before the exams.",
              "but the car broke down.")
NIGHTS = ("It was a good night for the team.", "We had a good night out in the old town.",
          "That was a good night's sleep.", "A good morning's work left the afternoon free.",
          "It took so long that we missed the bus.", "They waited so long for the letter that they gave up.",
          "Nobody had stayed so long at the party before.", "It was a good night for stargazing.")
MEETERS = ("The council", "The builders", "We", "The new clinic", "Few schools", "The factory", "Our team", "Farmers")
TARGETS = ("meet the deadline", "meet the target", "meet the demand", "meet the cost of repairs",
           "meet the new standard", "meet the needs of older patients", "meet the conditions of the loan")
MEET_TAILS = ("this year.", "without more money.", "for the first time.", "only after a long delay.",
              "in every district.", "despite the strike.")
CROWDS = ("The crowd", "The audience", "Everyone in the village", "The whole street", "My grandmother", "The class")
CHEERED = ("cheers for the home team.", "cheers for the runners as they pass.", "cheers up when the sun comes out.",
           "cheers for every goal, even the other side's.")
SHOWN = ("the new boiler", "the winning quilt", "our backyard pond", "the brand new tram", "the model of the bridge",
         "the garden we planted", "the cake for tonight", "my grandfather's watch", "the studio kitchen",
         "the robot arm", "the finished mural", "our smallest kitten", "the stage for the show",
         "the first printed copy", "the repaired piano", "the lab's new microscope", "the dress for the wedding")
THINGS = ("lamp", "kettle", "bicycle", "tractor", "greenhouse", "workshop", "cellar", "balcony", "fountain", "statue",
          "telescope", "printer", "drone", "guitar", "sofa", "teapot", "canoe", "lighthouse", "bakery", "classroom",
          "library", "garage", "chimney", "window seat", "treehouse", "trophy", "poster", "menu", "brochure",
          "blueprint", "timetable", "control room", "boardroom", "playground", "aquarium", "clock tower", "chapel",
          "vineyard", "barn", "stable", "pottery wheel", "loom", "sewing machine", "camera", "headset", "keyboard",
          "dashboard", "app", "website", "prototype", "sculpture", "painting", "quilt", "rug", "vase", "necklace",
          "ring", "cake", "pie", "soup", "bread", "salad", "plan for today", "schedule for the week", "agenda",
          "floor plan", "seating chart", "map of the site", "list of prizes")
NEW = ("new ", "", "", "finished ", "old ", "restored ", "brand new ", "little ", "main ", "")
SHOWN_MANY = ("the new bikes", "our tomatoes", "the costumes for the play", "the photos from the trip",
              "the tools we use", "the puppies", "the medals", "the vegetable beds")
SHOW_OPENERS = ("This is", "Here is", "Look at", "Take a look at", "Over there is", "Here we have",
                "Check out", "Have a look at", "Here's")
SHOW_PLACES = ("by the door", "on the left", "next to the window", "behind the fence", "in the corner",
               "across the road")
SHOW_TAILS = ("", ", right in front of you", ", finished only yesterday", ", just arrived this morning",
              " on the table", " behind me", ", fresh from the workshop")


def _pick(rng: random.Random, *choices: tuple[str, ...]) -> list[str]:
    return [rng.choice(options) for options in choices]


def _points(rng: random.Random) -> str:
    """"This is a familiar pattern that …", "These are the first … of …", "Here is one … nobody could agree on"."""
    opener, quality, noun, tail, ordinal = _pick(rng, ("This is a", "This is one", "This is another", "Here is a",
                                                       "Here is one", "This is the", "These are the", "Here we have a",
                                                       "Here's the"), QUALITIES, ABSTRACT, POINT_TAILS, ORDINALS)
    plural = opener.startswith("These")
    if opener.endswith("the") and rng.random() < 0.6:  # "the first …", "the first of many …", or "the part …"
        quality = f"{ordinal} {quality}" if rng.random() < 0.5 else f"{ordinal} of many "
        plural = plural or quality.endswith("many ")
    noun = f"{noun}s" if plural else noun
    return f"{opener} {quality}{noun} {tail}"


def _far_away(rng: random.Random) -> str:
    """"Over there, the monks still …": a place in the story, not a place to look."""
    people, doing = _pick(rng, PEOPLE, DOINGS)
    return rng.choice((f"Over there, {people} {doing}", f"Over there {people} {doing}",
                       f"{people.capitalize()} over there {doing}"))


def _welcome_adjective(rng: random.Random) -> str:
    noun, verb, reason = _pick(rng, WELCOMED, WELCOME_VERBS, WELCOME_FOR)
    return rng.choice((f"Welcome {noun} {verb}", f"It was a welcome {noun} {reason}", f"The welcome {noun} {verb}"))


GUESTS = ("hedgehogs", "birds", "frogs", "bees", "butterflies", "new ideas", "feedback", "questions", "criticism",
          "volunteers", "beginners", "rain", "early mistakes", "visitors")
INTO = ("into your garden", "to the pond", "from every member of the team", "at every stage of the project",
        "to the allotment", "in the first week", "to any meeting", "into the classroom")
BECAUSE = ("they keep the pests down.", "it saves time later.", "they often spot what others miss.",
           "the soil stays healthier.", "they are the quickest way to learn.", "nothing else works as well.")
BYE_NOUNS = ("weeks", "laws", "elections", "rounds", "runs", "products")
BYE_PREDICATES = ("give the players a chance to rest.", "change every few years.", "rarely make the news.",
                  "decide who reaches the final.", "apply to every village.", "used to be more common.")


def advice_sentences(rng: random.Random, count: int) -> list[str]:
    """``count`` sentences where "welcome" is a verb of advice ("Welcome hedgehogs into your garden, they keep the
    pests down") or "bye" opens a noun phrase ("Bye weeks give the players a chance to rest"): no act (the sixth
    revision)."""
    sentences = []
    for k in range(count):
        if k % 3:
            guests, into, because = _pick(rng, GUESTS, INTO, BECAUSE)
            sentences.append(f"Welcome {guests} {into}{rng.choice((', ', ' because '))}{because}")
        else:
            sentences.append(f"Bye {rng.choice(BYE_NOUNS)} {rng.choice(BYE_PREDICATES)}")
    return sentences


def _condition(rng: random.Random) -> str:
    """An imperative and a consequence: "Look at the census and the pattern is obvious" (if you look …)."""
    opener, evidence, consequence = _pick(rng, ("Look at", "Take a look at", "Have a look at"), EVIDENCE, CONSEQUENCES)
    return f"{opener} {evidence} and {consequence}"


def _phrase_inside(rng: random.Random) -> str:
    """"see you", "come on", greetings as nouns, wishes and "meet" inside an ordinary sentence."""
    kind = rng.randrange(6)
    if kind == 0:
        return " ".join(_pick(rng, SEERS, SEEING))
    if kind == 1:
        return " ".join(_pick(rng, DEVICES, SWITCHING))
    if kind == 2:
        return " ".join(_pick(rng, OWNERS, MANNERS, ACT_NOUNS, NOUN_TAILS))
    if kind == 3:
        return " ".join(_pick(rng, PLANNERS, PLANS, PLAN_TAILS))
    if kind == 4:
        return f"{rng.choice(MEETERS)} could not {rng.choice(TARGETS)} {rng.choice(MEET_TAILS)}"
    return rng.choice(NIGHTS) if rng.random() < 0.4 else " ".join(_pick(rng, CROWDS, CHEERED))


def narration_sentences(rng: random.Random, count: int) -> list[str]:
    """``count`` generated sentences, none an act, a fifth from each template family."""
    makers = (_points, _far_away, _welcome_adjective, _condition, _phrase_inside)
    return [makers[k % len(makers)](rng) for k in range(count)]


def presenting_sentences(rng: random.Random, count: int) -> list[str]:
    """``count`` sentences that present a thing there to see ("[guide]Here is the repaired piano, right in front of
    you."), the same openers as :func:`narration_sentences` before concrete things."""
    sentences = []
    for _ in range(count):
        opener, shown, tail, thing, new = _pick(rng, SHOW_OPENERS, SHOWN, SHOW_TAILS, THINGS, NEW)
        if rng.random() < 0.6:
            shown = f"{rng.choice(('the', 'our', 'my', 'this'))} {new}{thing}"
        if rng.random() < 0.2:
            opener, shown = rng.choice(("These are", "Here are", "Look at", "Check out")), rng.choice(SHOWN_MANY)
        elif rng.random() < 0.15:
            opener, tail = f"Over there, {rng.choice(SHOW_PLACES)}, is", ""
        sentences.append(f"[guide]{opener} {shown}{tail}.")
    return sentences
