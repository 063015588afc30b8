"""Cues decided from the phrase: candidates (recogniser spellings too), the grammar rules, the shipped classifier on
the phrasings users write, and words heard one at a time deciding the same as a transcript given at once."""

import numpy as np
import pytest

from gesturecast.controls import Word
from gesturecast.realtime.gestures.phrases import PhraseCues, PhraseListener, PhraseStream
from gesturecast.realtime.gestures.speech_acts import (
    ADDRESS_SENTENCES,
    ADDRESSED_PRESENTING,
    CLASSES,
    SpeechActClassifier,
    addressed,
    candidates,
    rule,
    tokenize,
)

GESTURES = ("wave", "wave-right", "hand-up", "bow", "raise-both", "guide", "call")


def words_of(text: str, step: float = 0.3) -> list[Word]:
    return [Word(token, i * step, (i + 1) * step) for i, token in enumerate(text.split())]


@pytest.fixture(scope="module")
def phrases() -> PhraseCues:
    return PhraseCues(GESTURES)


def test_recogniser_spellings_and_common_phrasings_are_candidates():
    tokens = tokenize(["Bye-bye,", "see", "ya!", "Good", "morning.", "Much", "appreciated,", "congrats,", "woohoo"])
    found = [(" ".join(t.text for t in tokens[c.start:c.stop]), c.intents) for c in candidates(tokens)]
    assert found == [("bye bye", ("farewell",)), ("see ya", ("farewell",)), ("good morning", ("greeting",)),
                     ("much appreciated", ("thanks",)), ("congrats", ("celebration",)), ("woohoo", ("celebration",))]


def test_wishes_introductions_and_places_are_candidates():
    text = "Have a lovely weekend. This is Ana. Meet Tom. On your left, step forward."
    tokens = tokenize(text.split(" "))
    found = [(" ".join(t.text for t in tokens[c.start:c.stop]), c.intents) for c in candidates(tokens)]
    assert found == [("have a lovely weekend", ("farewell",)), ("this is", ("presenting",)), ("meet", ("presenting",)),
                     ("on your left", ("presenting",)), ("step forward", ("calling",))]


@pytest.mark.parametrize("text", ["Thanks to the rain, this year looks better.",
                                  "Thanks to careful planning, the bridge opened on time.",
                                  "Thank goodness it stopped.", "Hi-fi shops were everywhere.",
                                  "He said hello to the postman.", "Come on is what he always said.",
                                  "Please come on time.", "Cheers rang out across the square.",
                                  "Come on, she thought, it cannot be that hard."])
def test_rules_rule_out_what_grammar_makes_clear(text):
    tokens = tokenize(text.split())
    assert [rule(tokens, c) for c in candidates(tokens)] == ["none"]


@pytest.mark.parametrize("text", [
    "Take care of the spare keys, please.", "Take care when the floor is wet.", "Take care not to spill it.",
    "Take care that the gate stays shut.", "Meet me outside the bakery.", "Meet us after lunch.",
    "Meet her at the gate.", "Here we have to slow down.", "This is why the roof leaks.",
    "Here is where the path ends.", "These are not the keys I lost.", "Look at any recipe from that time.",
    "Take a look at how the prices rose.", "Come along was the name of the song.",
    "Good night, the postcard from the island says.", "Cheerio and bye, the old porter would say.",
    "Hello, Tess, said her uncle.", "The guard shouted goodbye.", "Her brother told us goodbye.",
    "Goodbye, the captain announced over the crackling ship speaker at dawn.",
    "See you on Friday, we promised the neighbours before leaving.", "Hi and bye are the words my parrot knows."])
def test_what_follows_or_a_speaker_rules_a_speech_act_out(text):
    tokens = tokenize(text.split())
    assert [rule(tokens, c) for c in candidates(tokens)][:1] == ["none"]


@pytest.mark.parametrize("text", [
    "Take care of yourself on the road.", "Meet our new chef, Rosa.", "Here we have the winning cake.",
    "This is the new boiler.", "Look at this tiny kitten.", "Hi, I just want to say thanks.",
    "Much appreciated, to everyone who wrote to us.", "Welcome back, friends, as I said last week.",
    "Welcome, we say to every new member of the choir."])
def test_the_same_words_used_as_the_act_are_not_ruled_out(text):
    tokens = tokenize(text.split())
    assert rule(tokens, candidates(tokens)[0]) != "none"


@pytest.mark.parametrize("text, reported", [
    ("I want to say thank you to everyone.", False), ("Let me say hello to our guests.", False),
    ("We would like to tell you thanks for everything.", False), ("He wanted to say goodbye to his mother.", True),
    ("Please say hello to your mother.", True), ("They would like to say thanks.", True)])
def test_the_speakers_own_say_performs_the_act_anyone_elses_reports_it(text, reported):
    tokens = tokenize(text.split())
    assert (rule(tokens, candidates(tokens)[0]) == "none") == reported


def test_a_thank_you_to_people_is_left_to_the_classifier():
    tokens = tokenize(["Thanks", "to", "everyone", "who", "came", "tonight."])
    assert [rule(tokens, c) for c in candidates(tokens)] == [None]


@pytest.mark.parametrize("text, cued", [
    ("Hi, thanks for calling.", ["wave", "bow"]),
    ("Thanks to the rain, this year looks better.", []),
    ("Good morning, everyone!", ["wave"]),
    ("See ya, folks!", ["wave-right"]),
    ("Congrats on the new job!", ["raise-both"]),
    ("Much appreciated, thank you.", ["bow", "bow"]),
    ("I can see you nodding, so I will go on.", []),
    ("In the evening the street lights come on.", []),
    ("Is there anything else?", []),
    ("Come over here, quickly!", ["call"]),
    ("Have a great evening, everyone.", ["wave-right"]),
    ("Enjoy the rest of your day!", ["wave-right"]),
    ("Welcome, everyone. This is the new reading room.", ["wave", "guide"]),
    ("This is why we moved north.", []),
    ("Meet our new puppy, Biscuit.", ["guide"]),
    ("We meet on Fridays.", []),
])
def test_the_shipped_classifier_decides_from_the_phrase(phrases, text, cued):
    assert [cue.gesture for cue in phrases.cues(words_of(text))] == cued


def test_the_lexicon_decides_which_gesture_performs_an_intent():
    assert PhraseCues(("hand-up", "wave")).gesture_of("farewell") == "hand-up"
    assert PhraseCues(("wave",)).gesture_of("farewell") is None


def test_words_without_a_candidate_never_load_the_classifier():
    cues = PhraseCues(GESTURES)
    words = [Word("the", 0.0, 0.2), Word("street", 0.2, 0.5)]
    assert cues.cues([]) == [] and cues.cues(words) == []
    assert cues._classifier is None  # wordllama is loaded by the first candidate (or a live stream's warm-up)


def test_words_heard_one_at_a_time_cue_the_same_as_the_transcript(phrases):
    words = words_of("Hi, thanks for calling. Thanks to the rain we stayed in. Take care, and bye-bye for now.")
    listener = PhraseListener(phrases)
    heard = [cue for word in words for cue in listener.hear(word)] + listener.flush()
    assert heard == phrases.cues(words)
    assert [(cue.gesture, cue.source) for cue in heard] == [("wave", "Hi,"), ("bow", "thanks"),
                                                            ("wave-right", "Take care,"), ("wave-right", "bye-bye")]


@pytest.mark.parametrize("text", ["Goodbye, sun, said the boy.", "Hello, it says in a small voice every time.",
                                  "Take care of the maps, she said.", "See ya, the pirate sneered.",
                                  "Bye, he had written."])
def test_a_quote_attributed_within_three_words_is_no_cue_heard_either_way(phrases, text):
    words = words_of(text)
    listener = PhraseListener(phrases)
    heard = [cue for word in words for cue in listener.hear(word)] + listener.flush()
    assert heard == phrases.cues(words) == []


def test_an_interjection_alone_at_a_clause_start_is_its_act():
    tokens = tokenize(["Thank", "you,", "and", "goodbye!", "Hello", "and", "goodbye", "are", "words."])
    assert [rule(tokens, c) for c in candidates(tokens)] == ["thanks", "farewell", "none", "none"]


@pytest.mark.parametrize("text, act", [
    ("See you in court was written on the note.", "See you in court, and good luck."),
    ("Hello, stranger, is the first line of the film.", "Hello, stranger, come in."),
    ("Goodbye, was all she wrote.", "Goodbye, all of you."),
    ("Come on foot if you can.", "Come on, we are late."),
    ("Look at the map before you leave the car park.", "Look at the map, we are here."),
    ("Take a look at the label if the milk smells odd.", "Take a look at the label on this bottle."),
    ("Hi, this is Sam from the help desk.", "Hi, this is Sam, our new intern."),
    ("Welcome to the jungle was their biggest hit.", "Welcome everyone the show is about to start."),
    ("Hooray for Henry was the headline.", "Hooray the snow is here!"),
    ("Come on, we tell ourselves, it cannot last.", "Welcome, we tell every new member."),
    ("Thanks largely to the new manager, the club stayed up.", "Thanks largely for your patience.")])
def test_a_named_phrase_travel_advice_a_callers_name_and_a_cause_are_no_act(text, act):
    tokens = tokenize(text.split())
    assert rule(tokens, candidates(tokens)[-1]) == "none"
    tokens = tokenize(act.split())
    assert rule(tokens, candidates(tokens)[-1]) != "none"


@pytest.mark.parametrize("text, named", [("Hello, is the manager in?", False), ("Hello, is the first word.", True)])
def test_a_question_after_a_greeting_does_not_name_it(text, named):
    tokens = tokenize(text.split())
    assert (rule(tokens, candidates(tokens)[0]) == "none") == named


@pytest.mark.parametrize("text, since, presents", [
    ("These are the coldest nights of the year.", None, False),
    ("These are the coldest nights of the year.", 1, True),
    ("Over there, in a lab in Vienna, the effect was seen.", ADDRESS_SENTENCES + 1, False),
    ("Over there, by the door, is the cloakroom.", ADDRESS_SENTENCES, True),
    ("Look at this!", None, True), ("Take a look at these footprints.", None, True),
    ("Here is your key card.", None, True), ("Here is a detail from the second chapter.", None, False),
    ("Meet the new head of the lab.", None, True), ("On your left is the market.", None, True)])
def test_a_deictic_presenting_phrase_presents_only_to_someone_addressed(text, since, presents):
    tokens = tokenize(text.split())
    assert addressed(tokens, candidates(tokens)[0], since) == presents


@pytest.mark.parametrize("text, cued", [
    ("This is the third day of the trial. There was a long silence.", []),
    ("Hi, everyone. The shop opens at nine. This is our new coffee machine.", ["wave", "guide"]),
    ("Hi, everyone. One. Two. Three. This is our new coffee machine.", ["wave"]),
    ("Hi, everyone. This is our kitchen. This is our garden. This is our garage. This is our office.",
     ["wave", "guide", "guide", "guide"]),
    ("Hi, everyone. This is our kitchen. Meet our chef. This is our garage. This is our office.",
     ["wave", "guide", "guide", "guide", "guide"])])
def test_an_act_opens_the_sentences_where_this_is_presents_heard_either_way(phrases, text, cued):
    words = words_of(text)
    listener = PhraseListener(phrases)
    heard = [cue for word in words for cue in listener.hear(word)] + listener.flush()
    assert [cue.gesture for cue in heard] == [cue.gesture for cue in phrases.cues(words)] == cued


@pytest.mark.parametrize("text, since, intent", [
    ("Here is the plan for today.", 1, "presenting"), ("Here is the plan for today.", None, "none"),
    ("Here is the plan for today.", ADDRESS_SENTENCES + 1, "none"), ("Meet the new head of the lab.", 0, "none")])
def test_in_a_talk_a_deictic_phrase_presents_on_weaker_odds(text, since, intent):
    p = np.zeros(len(CLASSES))  # (classes,) just over the talk's threshold for presenting, the rest "none"
    p[CLASSES.index("presenting")] = ADDRESSED_PRESENTING + 0.05
    p[CLASSES.index("none")] = 1 - p.sum()
    tokens = tokenize(text.split())
    assert SpeechActClassifier._likeliest(tokens, candidates(tokens)[0], p, since) == intent


@pytest.mark.parametrize("messages", [
    ("Hi, everyone.", "This is our kitchen. One. Two.", "Three. This is our garden."),
    ("Hi,", "everyone. This is our kitchen. One.", "Two. Three. This is our garden.")])
def test_word_messages_carry_the_talk_over_as_one_transcript(phrases, messages):
    words = words_of(" ".join(messages))
    stream, at = PhraseStream(phrases), 0
    sent = []
    for message in messages:
        sent += stream.cues(words[at: at + len(message.split())])
        at += len(message.split())
    assert sent == phrases.cues(words)
    assert [cue.gesture for cue in sent] == ["wave", "guide"]


@pytest.mark.parametrize("text, phrase, intent", [
    ("Morning, all.", "morning", "greeting"), ("G'day, mate.", "g'day", "greeting"), ("Yo, Sam!", "yo", "greeting"),
    ("Good day, sir.", "good day", "greeting"), ("Thanks a million, Sam.", "thanks a million", "thanks"),
    ("Ta, love.", "ta", "thanks"), ("Much obliged, sir.", "much obliged", "thanks"),
    ("Night night, kids.", "night night", "farewell"), ("Peace out, folks!", "peace out", "farewell"),
    ("Safe journey, Tom.", "safe journey", "farewell"), ("Sweet dreams, love.", "sweet dreams", "farewell"),
    ("Hip hip hooray!", "hip hip hooray", "celebration"), ("Nailed it!", "nailed it", "celebration"),
    ("Fantastic, guys!", "fantastic", "celebration"), ("May I present the winner.", "may i present", "presenting"),
    ("Feast your eyes on this.", "feast your eyes on", "presenting"), ("This way, please.", "this way", "calling")])
def test_the_phrasebook_families_are_candidates(text, phrase, intent):
    tokens = tokenize(text.split())
    found = candidates(tokens)[0]
    assert (" ".join(t.text for t in tokens[found.start:found.stop]), found.intents) == (phrase, (intent,))


def first_rule(text: str) -> str | None:
    """What the rules decide for the first candidate phrase of ``text`` (words split at spaces)."""
    tokens = tokenize(text.split())
    return rule(tokens, candidates(tokens)[0])


@pytest.mark.parametrize("act, intent, ordinary", [
    ("Morning, all.", "greeting", "Morning traffic was light on the ring road."),
    ("Evening, everyone!", "greeting", "The evening news ran long."),
    ("Good day, sir.", "greeting", "It was a good day for the farmers."),
    ("Brilliant, the printer works!", "celebration", "It was a brilliant idea that nobody tried."),
    ("Let's go, team!", "celebration", "Let's go home before the rain starts."),
    ("This way, please.", "calling", "In this way the dough stays soft."),
    ("Ta, that was quick.", "thanks", "The ta of the drum kept time."),
    ("Yes! We won the quiz!", "celebration", "Yes, the figures are in, and they are poor."),
    ("Later, guys!", "farewell", "Later, the council changed its mind."),
    ("Later!", "farewell", "Later all the guests went home.")])
def test_an_interjection_word_is_its_act_only_standing_alone(act, intent, ordinary):
    assert first_rule(act) == intent
    tokens = tokenize(ordinary.split())
    assert [rule(tokens, c) for c in candidates(tokens)] == ["none"]


@pytest.mark.parametrize("act, ordinary", [
    ("Goodnight, everyone, drive safely.", "She gave him a goodnight kiss."),
    ("Come up to the front, all of you.", "The topic may come up again next year."),
    ("Everyone come up to the stage.", "Come up with a better plan and we will listen."),
    ("Behold the finished cathedral.", "The old castle was a sight to behold."),
    ("Sleep well, and see you in the morning.", "Babies sleep well in a cool room.")])
def test_a_phrase_that_must_open_its_clause_is_no_act_elsewhere(act, ordinary):
    assert first_rule(act) != "none"
    assert first_rule(ordinary) == "none"


@pytest.mark.parametrize("act, intent, ordinary", [
    ("Hip hip hooray for the twins!", "celebration", "Hip hip hooray was the headline on the back page."),
    ("Thanks ever so much for the lift.", "thanks", "Thanks ever so much, she said, and left."),
    ("Allow me to introduce our speaker.", "presenting", "Allow me to introduce is how every toast began."),
    ("Safe travels, and text us when you land.", "farewell", "The airline wished everyone safe travels."),
    ("Gather round, the story is starting.", "calling", "Gather round was the name of their first album.")])
def test_a_whole_phrase_opening_a_clause_is_its_act_unless_reported_quoted_or_named(act, intent, ordinary):
    assert first_rule(act) == intent
    assert first_rule(ordinary) != intent


def test_a_present_verb_of_saying_attributes_a_quote():
    tokens = tokenize(["Come", "on,", "the", "driver", "mutters", "at", "the", "red", "light."])
    assert rule(tokens, candidates(tokens)[0]) == "none"


@pytest.mark.parametrize("text, cued", [
    ("Thanks a million, Sam.", ["bow"]), ("Morning traffic was light.", []), ("Goodnight, everyone!", ["wave-right"]),
    ("She gave him a goodnight kiss.", []), ("Brilliant, you did it!", ["raise-both"]),
    ("It was a brilliant idea.", []), ("Take a seat. Behold the finished cathedral.", ["guide"])])
def test_the_shipped_classifier_with_the_phrasebook(phrases, text, cued):
    assert [cue.gesture for cue in phrases.cues(words_of(text))] == cued
