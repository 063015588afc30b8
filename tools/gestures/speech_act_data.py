"""Training sentences of the speech-act classifier (:mod:`gesturecast.realtime.gestures.speech_acts`).

Written for it, and kept apart from the benchmark's texts (``tools/bench/gesture_set/texts.py``), which nothing here
reads. ``[gesture]`` marks the word that opens an intended gesture (the same convention as the benchmark); every
other candidate phrase in a sentence ("there are", "thanks to the", "see you running") is a "none" example.
:func:`training_sentences` combines the openers of each speech act with continuations, and adds the sentences where
the same words are not a speech act, seeded, so the set is the same on every run.
"""

from __future__ import annotations

import random

from gesturecast.tools.gestures.speech_act_narration import (
    advice_sentences,
    narration_sentences,
    presenting_sentences,
)
from gesturecast.tools.gestures.speech_act_phrasebook import phrasebook_acts, phrasebook_ordinary

ADDRESSEES = ("everyone", "folks", "friends", "all", "guys", "team", "Sam", "Priya", "Doctor Lee", "class",
              "ladies and gentlemen", "you two", "everybody", "my friend", "neighbours")
FILLERS = ("The weather has been strange lately.", "We have a lot to get through.", "The train was late again.",
           "Our guest today writes about rivers.", "Let me start with the news.", "It has been a long week.",
           "The results came in this morning.", "I brought some notes with me.", "The room is almost full.",
           "We start in five minutes.", "Nobody saw the storm coming.", "The coffee is still warm.")
GREETINGS = ("Hello", "Hi", "Hey", "Hiya", "Howdy", "Good morning", "Good afternoon", "Good evening", "Welcome",
             "Greetings", "Hello there", "Hi there", "Hey there")
GREETING_TAILS = ("{a}!", "{a}, nice to see you.", "and [wave]welcome to the meeting.", "{a}, how are you doing?",
                  "to all our listeners.", "{a}, glad you could join us.", "from all of us here.",
                  "{a}, come in and sit down.", "and [bow]thanks for tuning in.", "again, {a}.", "there, {a}.",
                  "to our new members.", "{a}, it's been a while.", "back to the programme.", "aboard, {a}.",
                  "home, {a}!", "in, {a}, make yourselves at home.", "along, {a}.")  # "welcome aboard/home/in/along"
THANKS = ("Thank you", "Thanks", "Many thanks", "Much appreciated", "Cheers", "Thank you very much",
          "Thanks a lot", "Thanks so much", "Thank you so much")
THANKS_TAILS = ("for coming today.", "{a}.", "for your help with the move.", "for the lovely flowers.",
                "to all of you who volunteered.", "for waiting.", "{a}, that means a lot.", "for the feedback.",
                "for listening.", "to everyone who donated.", "for the ride home.", "again, {a}.",
                "for having me on the show.", "to our sponsors for their support.")
THANK_VERBS = ("I want to [bow]thank {a} for coming.", "We [bow]thank you for your time.",
               "I'd like to [bow]thank our hosts tonight.", "Let me [bow]thank the organisers first.",
               "I really [bow]thank you for this.", "I can't [bow]thank you enough.")
FAREWELLS = ("Bye", "Goodbye", "Good bye", "Bye bye", "Bye-bye", "See you", "See ya", "Farewell", "Take care",
             "So long", "Good night", "Have a nice day", "Have a good day", "Have a great day", "Catch you later")
FAREWELL_TAILS = ("{a}!", "and drive safely.", "for now.", "later, {a}.", "tomorrow.", "next week, {a}.",
                  "{a}, until next time.", "and sleep well.", "soon!", "around, {a}.", "on Monday.",
                  "and [bow]thanks again.", "everyone, and good luck.", "then!", "at dinner, {a}.",
                  "at the match on Saturday.", "in the morning, {a}.", "in class tomorrow.", "at school.",
                  "in a bit, {a}.")  # "see you at/in" a time or a place
WISH_FAREWELLS = ("Have a nice evening", "Have a good weekend", "Have a lovely day", "Have a wonderful evening",
                  "Have a safe trip", "Have a pleasant journey", "Have a great weekend", "Have a good night",
                  "Have a nice afternoon", "Have a great time", "Enjoy the rest of your day", "Enjoy your evening",
                  "Enjoy your weekend", "Safe travels", "Until next time", "Talk soon", "Take it easy")
WISH_TAILS = ("{a}!", "and drive safely.", "and see you soon.", "everyone.", "and [bow]thanks again.", "{a}, bye.",
              "all of you.", "and come back soon.", "{a}, it was a pleasure.", "and good luck with the move.")
CELEBRATIONS = ("Hooray", "Hurray", "Hurrah", "Yay", "Woohoo", "Woo hoo", "Congratulations", "Congrats",
                "Well done", "Bravo", "Yippee")
CELEBRATION_TAILS = ("we made it!", "{a}!", "to the winners!", "the tests passed!", "it's finally Friday!",
                     "on your new job, {a}!", "we are through to the next round!", "that was amazing!",
                     "on the wedding!", "you did it, {a}!", "the snow is here!", "to the whole crew!")
PRESENTING = ("[guide]Look at this", "[guide]Look at", "[guide]Take a look at", "[guide]Have a look at",
              "[guide]Check out", "[guide]Here is", "[guide]Here are", "[guide]Over there is",
              "[guide]Here you can see", "[guide]This is our", "[guide]These are our", "[guide]Here we have")
MORE_PRESENTING = ("[guide]This is", "[guide]These are", "[guide]Let me show you", "[guide]On your right is",
                   "[guide]To your left you can see", "[guide]Allow me to introduce", "[guide]Let me introduce",
                   "[guide]May I introduce", "[guide]Over there you can see", "[guide]Over there, by the door, is",
                   "[guide]Over there, next to the stage, are", "[guide]Right here is")  # added in the third revision
PRESENTED = ("the new logo.", "the first sketch of the garden.", "our sales figures for the year.",
             "the view from the top floor.", "the prototype we built.", "this little machine.",
             "the photo from the launch.", "the results of the survey.", "the map of the old town.",
             "our new kitchen.", "the winning design.", "the chart on the screen.", "the oldest tree in the park.",
             "my colleague Jonas, who runs the lab.", "the engine room.", "the seeds we collected in May.")
INTRODUCED = ("[guide]Meet Lena, our head chef.", "[guide]Meet the team behind the app.",
              "[guide]Meet our newest volunteer, Omar.", "[guide]Meet the robot that sorts the mail.",
              "Everyone, [guide]meet Professor Diaz.", "Please [guide]meet my sister, Carla.",
              "[guide]This is Nadia, who built the website.", "[guide]These are the twins I told you about.",
              "[guide]This is the kitchen, where the magic happens.", "[guide]This is the new studio.")
CALLING = ("Come here", "Come on", "Come over here", "Come closer", "Over here", "Gather round", "Gather around",
           "Come along", "Come on over", "Come over", "Come forward", "Come on up", "Come up here", "Come join us",
           "Step forward")
CALLING_TAILS = ("{a}, quickly!", "and sit with us.", "{a}, I want to show you something.", "we're starting.",
                 "and have a look.", "{a}, don't be shy.", "the food is ready.", "everybody, it's time.",
                 "{a}, you can see better from here.", "and grab a chair.")
NOT_ACTS = (  # the candidate words, not a speech act: none of them opens a gesture
    "There are four bridges across the river.", "There is a cafe at the corner of the square.",
    "There was nobody left in the office.", "There were hundreds of people at the concert.",
    "Is there a faster way to do this?", "Are there any tickets left for Sunday?",
    "There seems to be a mistake in the bill.", "There will be snow in the mountains.",
    "There has been a lot of talk about the plan.", "There might be a delay on the northern line.",
    "Thanks to the new bus lane, the trip is shorter.", "Thanks to a late goal, the visitors won.",
    "Thanks to this rule, fewer people get lost.", "Thanks to its thick walls, the house stays cool.",
    "Thank goodness the dog came home.", "Thank heavens it did not rain on the parade.",
    "The kettle switched off before the water could come on to boil.", "The radio will come on at six.",
    "The heater did not come on all night.", "Please come on time tomorrow.", "The actors come on stage in pairs.",
    "The street lamps come on at dusk.", "A cold can come on very suddenly.", "The warning light came on twice.",
    "I can see you are busy, so I will be quick.", "They could see you were tired.",
    "We see you working late every night.", "I will see you get the refund.",
    "You will see your bill in the post.", "I'll see you in court, he told the landlord.",
    "He said hello to every child at the gate.", "She waved goodbye to the ship.",
    "They said goodbye at the station.", "We bid farewell to the old manager last year.",
    "He wished them a nice day and left.", "The welcome desk opens at nine.",
    "It was a welcome change from the usual food.", "The welcome letter was three pages long.",
    "Hi-fi shops were everywhere in the eighties.", "The hi-res photos took ages to load.",
    "This is the reason the road was closed.", "This is how the engine starts.",
    "This is why nobody trusts the forecast.", "This is the second time it has happened.",
    "This year the lake froze early.", "This summer we painted the fence.", "This method saves a lot of water.",
    "These numbers went up last spring.", "These days nobody writes letters.",
    "Here in the north, the nights are long.", "Here and there, a few trees were still green.",
    "Here the road turns toward the coast.", "It is here that the canal meets the sea.",
    "We came here in nineteen eighty.", "Life here is quiet and slow.", "They have lived here for years.",
    "Over there in the valley, farmers grow wheat.", "Nobody lives there any more.",
    "If we look at the history, the pattern is clear.", "Scientists look at the data every week.",
    "The report takes a look at rising prices.", "Doctors check out every patient twice.",
    "She thanked the nurses in her speech.", "He thanks his parents in the preface.",
    "The crowd cheers when the band walks on.", "Cheers went up from the stands.",
    "The congratulations arrived a week late.", "A yay or nay vote follows the debate.",
    "Well done steak takes longer to cook.",
    "Take care of the plants while I am away.", "They take care of their grandmother.",
    "So long as the sun shines, we will be fine.",
    "The hello kitty bag was a gift.", "Say hello to your sister for me.",
    "The bus should come along any minute now.",
    "The tide will come in over the rocks.", "The neighbours come over for dinner on Sundays.",
    "Prices will come closer to normal next year.", "The children gather around the fire at night.",
    # the candidate opens the sentence but names a thing (added in the second revision)
    "Welcome rain fell on the dry fields.", "Welcome guests receive a small gift at the door.",
    "Welcome signs were put up along the road.", "Cheers erupted when the goal was scored.",
    "Cheers rang out across the square.", "Thanks were given to the volunteers at the end.",
    "Thank you notes were sent to every guest.", "Hello and goodbye are the first words children learn.",
    "Goodbye letters were found in the drawer.", "Farewell speeches tend to go on too long.",
    "Bravo was the only word the critic wrote.", "Congratulations poured in from abroad.",
    "If you look at the budget, the numbers are clear.", "Hooray headlines filled the papers the next day.",
    "Greetings cards sell best in December.", "Take care homes are short of staff.",
    # the phrases added with the farewell wishes, "this is", "meet" and the places (the third revision)
    "This is a problem for small farms.", "This is not what the council promised.",
    "This is where the plan falls apart.", "This is what happens when nobody checks the numbers.",
    "This is a good example of a bad law.", "This is the best part of the job.",
    "This is one reason prices keep rising.", "This is a book about patience.",
    "These are the years when the town grew fastest.", "These are difficult questions for any government.",
    "We meet every second Tuesday in the library.", "The two roads meet at the edge of the forest.",
    "The ministers will meet again after the summer.", "Our plans did not meet the deadline.",
    "It is hard to meet the cost of heating.", "I hope to meet her parents one day.",
    "They want to have a nice day out at the lake.", "Did you have a good weekend?",
    "We will have a great time in the mountains.", "Kids need to have a good night of sleep.",
    "He told us to have a safe trip and hung up.", "The tourists have a pleasant evening in the square.",
    "Keep the river on your left for two miles.", "The bakery is on your right after the bridge.",
    "Turn to your left at the church.", "Witnesses were asked to come forward.",
    "Few people dared to step forward at the meeting.", "The topic may come up again next year.",
    "Nice to meet you, I am the new tenant.", "You should take it easy after surgery.",
    "Talk soon turned to the weather.", "Until next time the rules stay as they are.",
)


EXPLAINED = ("the moment", "the point", "the reason", "the way", "the kind of thing", "the first time", "the part",
             "the problem", "the question", "the end of the story", "the only way", "the last time", "a problem",
             "a question", "a reminder", "a lesson", "a chance", "a sign", "not", "why", "how", "where", "what",
             "when", "because", "one of the reasons", "exactly", "just", "about", "the same mistake", "a story")
EXPLAINING = ("we have been waiting for.", "that nobody talks about.", "everyone remembers.", "it all changed.",
              "the plan failed.", "we need to discuss.", "the experts disagree.", "things went wrong.",
              "that matters most.", "the town was founded.")


EXPLAINED_MANY = ("the reasons", "the questions", "the years", "the kinds of problems", "the risks", "the rules",
                  "the ideas", "the choices", "difficult times", "not the only reasons", "the lessons", "the details")


def _explanations(rng: random.Random, count: int) -> list[str]:
    """``count`` sentences where "this is" or "these are" opens an explanation, not a thing shown ("This is why it
    failed", "These are the reasons"): the presenting one names something there to see (added in the third
    revision)."""
    return [f"This is {rng.choice(EXPLAINED)} {rng.choice(EXPLAINING)}" if k % 3 else
            f"These are {rng.choice(EXPLAINED_MANY)} {rng.choice(EXPLAINING)}" for k in range(count)]


CONTINUATIONS = frozenset(["for", "to", "and", "on", "later", "tomorrow", "next", "there", "again", "around", "soon",
                           "then", "from", "back", "aboard", "home", "in", "along", "at"])
JOINERS = (", ", " ", "! ", ", ")
NARRATION_PER_ACT = 3  # generated narration sentences per act sentence count (the fourth revision)


NOUN_OPENERS = ("Welcome", "Cheers", "Thanks", "Goodbye", "Farewell", "Hello", "Congratulations", "Hooray",
                "Bravo", "Greetings", "Take care", "Come on")  # opening a noun phrase that is the subject
SUBJECT_NOUNS = ("parties", "speeches", "messages", "tours", "cards", "letters", "songs", "shouts", "signs", "calls",
                 "banners", "gifts")
PREDICATES = ("were held in the old hall.", "became popular after the war.", "filled the square that night.",
              "are less common than they used to be.", "went on for hours.", "made the evening news.",
              "cost more than anyone expected.", "were printed in three languages.", "drew a large crowd.",
              "have a long history in the region.")


def _noun_phrase_sentences(rng: random.Random, count: int) -> list[str]:
    """``count`` sentences whose subject opens with a candidate used as a noun or adjective ("Farewell tours
    became popular"): none of them is a speech act (added in the second revision)."""
    return [f"{rng.choice(NOUN_OPENERS)} {rng.choice(SUBJECT_NOUNS)} {rng.choice(PREDICATES)}" for _ in range(count)]


def _fill(text: str, rng: random.Random) -> str:
    return text.replace("{a}", rng.choice(ADDRESSEES))


def _acts(rng: random.Random, openers: tuple[str, ...], tails: tuple[str, ...], gesture: str, count: int) -> list:
    """``count`` sentences: an opener marked with ``[gesture]`` and a continuation, some after a filler."""
    sentences = []
    for _ in range(count):
        opener = rng.choice(openers)
        act = opener if "[" in opener else f"[{gesture}]{opener}"
        tail = _fill(rng.choice(tails), rng)
        joiner = " " if tail.split()[0] in CONTINUATIONS else rng.choice(JOINERS)
        sentence = f"{act}{joiner}{tail}"
        if rng.random() < 0.3:
            sentence = f"{rng.choice(FILLERS)} {sentence}" if rng.random() < 0.5 else \
                f"{sentence} {rng.choice(FILLERS)}"
        sentences.append(sentence)
    return sentences


def training_sentences(seed: int = 0, per_act: int = 220) -> list[str]:
    """The whole training set: ``per_act`` sentences per speech act (half as many farewell wishes, and the
    introductions three times each), the verb forms of thanks, every
    :data:`NOT_ACTS` sentence three times (alone, after and before a filler), ``per_act // 2`` sentences whose
    subject opens with a candidate and as many where "this is" opens an explanation, ``NARRATION_PER_ACT · per_act``
    generated narration sentences and ``per_act`` generated presenting ones
    (:mod:`gesturecast.tools.gestures.speech_act_narration`, the fourth revision), and ``per_act // 2`` where
    "welcome" advises and "bye" opens a noun phrase (the sixth revision), and every phrasebook phrase as its act
    twice and its words in ordinary narration (:mod:`gesturecast.tools.gestures.speech_act_phrasebook`, the
    phrasebook revision)."""
    rng = random.Random(seed)
    sentences = (_acts(rng, GREETINGS, GREETING_TAILS, "wave", per_act)
                 + _acts(rng, THANKS, THANKS_TAILS, "bow", per_act)
                 + _acts(rng, FAREWELLS, FAREWELL_TAILS, "bye", per_act)
                 + _acts(rng, CELEBRATIONS, CELEBRATION_TAILS, "raise-both", per_act)
                 + _acts(rng, CALLING, CALLING_TAILS, "call", per_act)
                 + _acts(rng, WISH_FAREWELLS, WISH_TAILS, "bye", per_act // 2)
                 + [f"{_fill(o, rng)} {rng.choice(PRESENTED)}" for o in PRESENTING for _ in range(per_act // 12)]
                 + [f"{o} {rng.choice(PRESENTED)}" for o in MORE_PRESENTING for _ in range(per_act // 24)]
                 + [text for text in INTRODUCED for _ in range(3)]
                 + [_fill(t, rng) for t in THANK_VERBS for _ in range(4)])
    for text in NOT_ACTS:
        sentences += [text, f"{rng.choice(FILLERS)} {text}", f"{text} {rng.choice(FILLERS)}"]
    return (sentences + _noun_phrase_sentences(rng, per_act // 2) + _explanations(rng, per_act // 2)
            + narration_sentences(rng, per_act * NARRATION_PER_ACT) + presenting_sentences(rng, per_act)
            + advice_sentences(rng, per_act // 2) + phrasebook_acts(rng) + phrasebook_ordinary())
