"""Gesture cues decided from the phrase, not the word: is "thanks" a thank-you, or "thanks to the rain"?

A cue is a speech act: a greeting (wave), thanks (bow), a farewell (a one-hand wave, ``wave-right``; Bandai's
``bye``, a hand held up (``hand-up``), is the fallback), a celebration (raise-both), presenting something (guide) or
calling someone over (call). :data:`CANDIDATES` lists the phrases that can open one ("good
morning", "see ya", "bye bye": "Bye-bye" as recognisers write it is two tokens). Each occurrence is then decided
from the sentence around it:

1. **Rules** where the grammar is clear (:func:`rule`): a causal "thanks to the rain" or "thanks to careful
   planning, the bridge opened"; "thank goodness"; a phrase inside a hyphenated word ("hi-fi"); reported speech
   ("said hello", "waved goodbye"); a phrase mentioned, not used ("come on is what he said"); "come on time" and
   "come on stage"; "cheers" neither alone nor followed by "for" or "to" (the crowd's); quoted words with their
   speaker after a comma ("Come on, she thought", "Goodbye, sun, said the boy", "Have a nice day, the sign in the
   window says"); what follows making the phrase ordinary English (:func:`not_the_act`: "take care *of* the maps",
   "meet *me* at noon", "here we have *to*", "this is *why*", "look at *any* map", "look at the map *before you
   leave*"); a phrase named rather than said (:func:`named`: "See you in court was written", "Hello, stranger, is
   the first line"); "come on foot"; and the other way, an interjection standing alone at the start of a clause
   ("Hooray!", "and goodbye!") is its act. Presenting is cued by its phrases ("here is", "look at", "over there",
   "this is", "meet", "on your left"), never by a bare "this", "there" or "here"; "this is" opens presenting ("This
   is the frame") as often as an explanation ("This is why"), so the classifier decides it, and a deictic phrase
   presents only to someone addressed (:func:`addressed`: within three sentences of another act, or "look at
   *this*", "here is *your* key"): narration says "this is the third day of the trial" without one. In a talk
   the same phrase presents from a presenting probability of :data:`ADDRESSED_PRESENTING` on.
2. **A small classifier** for the rest (:class:`SpeechActClassifier`): softmax regression over the packaged
   wordllama text embedding (numpy only) of the phrase's window, the words before and after it and the single
   words next to it, plus where it stands (opening the sentence or a clause, punctuation after it). It is trained
   on sentences written for it (:mod:`gesturecast.tools.gestures.speech_act_data`, ``gesturecast gestures
   train-acts``), never on the benchmark's texts; its weights ship in ``models/weights/gestures/speech_acts.npz``.

The decision needs :data:`AFTER_TOKENS` words after the phrase, or the end of its sentence: what follows decides
("see you *walking*", "lights come *on*"). Words are only read inside their sentence, so a transcript given at once
and the same words reported one at a time give the same cues, but for one rule: a quote's attribution (:func:`quoted`)
more than :data:`AFTER_TOKENS` words after the phrase is read only where the sentence is already there (a
transcript); words one at a time decide before it arrives, so the classifier decides such a quote.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from gesturecast.errors import UserError
from gesturecast.realtime.gestures.phrasebook import ADDRESSEES, NOT_AFTER, PHRASEBOOK, placement

INTENT_GESTURES = {  # intent -> the lexicon gestures that perform it, the first the lexicon has wins
    "greeting": ("wave",), "thanks": ("bow",), "farewell": ("wave-right", "hand-up"), "celebration": ("raise-both",),
    "presenting": ("guide",), "calling": ("call",)}
MARKS = {"wave": "greeting", "bow": "thanks", "bye": "farewell", "raise-both": "celebration", "guide": "presenting",
         "call": "calling"}  # ``[mark]`` in marked sentences (training, benchmark) -> the intent it stands for
CLASSES = ("none", *INTENT_GESTURES)
CANDIDATES = PHRASEBOOK  # intent -> phrases (normalised tokens) that can open it (gestures/phrasebook.py)
AFTER_TOKENS = 3  # words after the phrase the decision reads (fewer at the end of its sentence)
BEFORE_TOKENS = 3  # words before it
WINDOW_TOKENS = 4  # the window's words on each side of the phrase
SENTENCE_END = re.compile(r"[.!?]+[\"')\]]*$")
CLAUSE_END = re.compile(r"[,;:—–-]+[\"')\]]*$")
TOKEN = re.compile(r"[\w']+")
BE = frozenset(["is", "are", "was", "were", "be", "been", "will", "would", "seems", "seem", "seemed", "has", "have",
                "had", "might", "must", "may", "could", "should", "used", "isn't", "aren't", "wasn't", "weren't"])
CAUSAL_AFTER = frozenset(["the", "a", "an", "this", "that", "its", "it"])
DEGREES = frozenset(["largely", "partly", "mostly", "mainly", "chiefly", "entirely", "only", "partially", "solely"])
NOT_THANKS = frozenset(["goodness", "god", "heavens", "heaven"])
REPORTING = frozenset(["say", "said", "says", "saying", "wave", "waved", "waves", "waving", "bid", "bade", "bidding",
                       "wish", "wished", "shouted", "cried", "called", "whispered", "yelled", "muttered", "wrote",
                       "writes", "read", "reads", "answered", "replied", "added", "told", "tell", "tells"])
COME_ON_PLACES = frozenset(["time", "stage", "board", "air", "duty", "top", "line", "screen", "camera", "again",
                            "foot", "horseback", "bikes", "skis"])  # "come on time", "come on foot"
ATTRIBUTION = frozenset(["said", "says", "say", "asked", "asks", "ask", "argued", "argues", "thought", "thinks",
                         "wrote", "writes", "shouted", "shouts", "shout", "replied", "replies", "added", "adds",
                         "explained", "explains", "told", "tells", "cried", "cries", "whispered", "whispers",
                         "muttered", "insisted", "suggested", "suggests", "called", "calls", "yelled", "warned",
                         "warns", "promised", "promises", "announced", "announces", "advised", "groaned", "sighed",
                         "laughed", "joked", "remarked", "noted", "notes", "answered", "complained", "declared",
                         "declares", "exclaimed", "began", "begins", "urged", "screamed", "murmured", "read", "reads",
                         "recalled", "recalls", "repeated", "mumbled", "snapped", "grumbled",
                         "tell", "mutters", "murmurs", "mumbles", "grumbles", "snaps", "sighs", "groans", "laughs",
                         "jokes", "yells", "screams", "exclaims", "insists", "complains", "remarks",
                         "repeats",
                         "sneered", "sneers", "snarled", "snarls", "hissed", "hisses", "growled", "growls",
                         "chuckled", "chuckles", "teased", "teases", "scoffed", "scoffs", "gasped", "gasps",
                         "boomed", "booms", "roared", "roars", "barked", "barks", "quipped", "quips", "retorted",
                         "retorts", "stammered", "stammers", "texted", "texts", "typed", "types", "scrawled",
                         "scribbled", "written", "spoken", "sung", "sang", "sings"])  # verbs of saying (the
# phrasebook revision: every past form's present too; the last revision: manners of saying and the participles
# after "had" / "has": "See you in court, the defendant had written")
PAST_SAYING = frozenset(["said", "told", "wrote", "thought", "began", "written", "spoken", "sung", "sang"])
REFLEXIVE_SELF = frozenset(["myself", "ourselves", "yourself", "yourselves"])  # a quote said to oneself
ATTRIBUTION_CLAUSE = 7  # a clause of at most this many words after the quote that holds a verb of saying
ATTRIBUTION_CLOSING = 12  # … or of at most this many that a verb of saying closes ("the sign in the window says.")
CLAUSES_AFTER_QUOTE = 2  # "Goodbye, sun, said Pip": the attribution may follow an address
NOT_ATTRIBUTION = frozenset(["and", "but", "as", "where", "which", "who", "because", "if", "when", "so", "while",
                             "that", "since", "although", "though", "or", "to", "for", "of", "in", "on", "at",
                             "with", "from"])  # a clause these open is no attribution
PERFORMATIVE_VERBS = frozenset(["say", "tell", "wish", "bid", "wave"])  # base forms a speaker performs with
SPEAKERS = frozenset(["i", "we", "let", "let's", "i'd", "we'd", "i'll", "we'll"])
PERFORMATIVE_LEAD = frozenset([*SPEAKERS, "me", "us", "just", "also", "really", "only", "first", "want", "wanted",
                               "to", "like", "would", "must", "can", "could", "should", "and", "so", "now", "all",
                               "both", "again", "once", "quickly", "briefly", "personally", "simply", "do"])
FIRST_PERSON = frozenset(["i", "we", "you"])  # "Hi, I want to say": an attribution only in the past ("we promised")
SPEAKER_WORDS = 3  # "a painted board announced …": the verb of saying follows a speaker of at most this many words
RELATIVES = frozenset(["who", "that", "which", "whom"])  # "to all of you who wrote in": the verb is not the quote's
OBJECTS = frozenset(["me", "us", "him", "them", "you"])  # "meet me at the station" arranges, does not introduce
ARRANGING = frozenset(["at", "in", "on", "after", "before", "outside", "inside", "by", "near", "for", "with", "there",
                       "here", "tomorrow", "tonight", "today", "again", "soon", "halfway", ""])  # "meet her at noon"
CARE_COMPLEMENTS = frozenset(["of", "to", "that", "when", "not", "while", "if", "with", "in", "on", "about",
                              "because", "how", "what", "whether", "before", "after", "during", "where"])
REFLEXIVES = frozenset(["yourself", "yourselves"])  # "take care of yourself" is still a farewell
EXPLAINING = frozenset(["where", "how", "what", "why", "when", "who", "which", "whose", "because", "not", "no",
                        "never", "just", "exactly", "precisely", "also", "partly", "probably", "perhaps", "still",
                        "only", "nothing", "hardly", "largely", "mostly", "certainly", "surely", "clearly"])
GENERIC = frozenset(["any", "every", "how", "what", "why", "whether", "where", "who", "which", "most", "almost",
                     "nearly", "each"])  # "look at any map": nothing there to point at
SUBJECT_BE = frozenset(["is", "was", "are", "were"])
SUBJECT_WORDS = 3  # "See you in court was written": at most this many words between the phrase and its verb
OWN_SUBJECTS = frozenset(["it", "this", "that", "he", "she", "they", "we", "i", "you", "there", "who", "which", "what",
                          "where", "when", "how", "if", "because", "everyone", "everybody", "all", "folks", "guys",
                          "friends", "team", "ladies", "kids", "children", "us"])  # the verb has a subject of its own,
# or the phrase an addressee ("Hi everyone the weather is lovely", as a recogniser may write it)
NAMED = frozenset(["the", "a", "an", "all", "one"])  # "Hello, stranger, is *the* first line": the phrase is named
ADVICE = frozenset(["before", "after", "if", "when", "while", "until", "once", "whenever", "unless"])  # "look at the
# map before you leave": advice, nothing shown
CALLERS = frozenset(["from", "speaking", "calling", "here"])  # "this is Sam *from* support": a caller's own name
ADDRESS_SENTENCES = 3  # a deictic presenting phrase presents only this many sentences after another act (decide)
ADDRESSED_PRESENTING = 0.3  # … and there from this probability of presenting on (_likeliest)
DEICTIC = frozenset(["this is", "these are", "this is our", "these are our", "this is my", "here is", "here are",
                     "here's", "here we have", "here you can see", "over there", "look at", "take a look",
                     "have a look", "check out"])  # presenting phrases that narration uses as often
POINTING = frozenset(["this", "these", "that", "those", "your"])  # "look at this", "here is your key": shown anyway
MAIN_CLAUSE_TOKENS = 3  # words after the comma that make a main clause
OPENERS = frozenset(["and", "so", "oh", "well", "but", "now"])  # a speech act may follow these at a clause start
FEATURE_VERSION = 3
CONTEXTS = 6  # texts embedded per candidate (context_texts)
DETERMINERS = frozenset(["the", "a", "an", "our", "my", "your", "this", "these", "that", "those", "its", "their",
                         "his", "her", "one", "another", "some"])  # skipped to the head word after the phrase


@dataclass(frozen=True)
class Token:
    """One word token: its text (lower case), the index of the transcript word it came from, whether punctuation
    follows it (",", "." …), whether it ends a sentence, whether a hyphen joins it to the next token, whether a
    question mark or an exclamation mark follows it, and whether its mark was read from a pause, not written."""

    text: str
    word: int
    clause_end: bool
    sentence_end: bool
    hyphen: bool
    question: bool = False  # a question mark follows it
    exclaimed: bool = False  # an exclamation mark follows it
    paused: bool = False  # its mark was read from a pause (gesturecast.realtime.words.punctuation)


@dataclass(frozen=True)
class Candidate:
    """A phrase of :data:`CANDIDATES` at tokens ``[start, stop)``, with the intents it can open."""

    start: int
    stop: int
    intents: tuple[str, ...]


def tokenize(texts: list[str], paused: frozenset[int] = frozenset()) -> list[Token]:
    """Transcript words → tokens ("Bye-bye," → "bye" joined by a hyphen to "bye", then a clause end); ``paused``: the
    words whose marks were read from their pauses."""
    tokens = []
    for index, text in enumerate(texts):
        parts = list(TOKEN.finditer(text.lower()))
        for k, part in enumerate(parts):
            tail = text[part.end(): parts[k + 1].start() if k + 1 < len(parts) else len(text)]
            last = k + 1 == len(parts)
            tokens.append(Token(part.group(), index, bool(CLAUSE_END.search(tail)) or (last and bool(
                SENTENCE_END.search(tail))), last and bool(SENTENCE_END.search(tail)), "-" in tail and not last,
                last and "?" in tail, last and "!" in tail, last and index in paused))
    return tokens


@cache
def phrase_table() -> dict[tuple[str, ...], tuple[str, ...]]:
    """Phrase tokens → the intents it can open."""
    table: dict[tuple[str, ...], tuple[str, ...]] = {}
    for intent, phrases in CANDIDATES.items():
        for phrase in phrases:
            table[tuple(phrase.split())] = (*table.get(tuple(phrase.split()), ()), intent)
    return table


def candidates(tokens: list[Token]) -> list[Candidate]:
    """Every candidate phrase in ``tokens``, the longest first where several start at a token; a phrase never
    runs over a sentence end."""
    table = phrase_table()
    longest = max(len(p) for p in table)
    found, index = [], 0
    while index < len(tokens):
        for length in range(min(longest, len(tokens) - index), 0, -1):
            words = tuple(t.text for t in tokens[index: index + length])
            inside = not any(t.sentence_end for t in tokens[index: index + length - 1])
            if inside and words in table:
                found.append(Candidate(index, index + length, table[words]))
                index += length
                break
        else:
            index += 1
    return found


def phrase_of(tokens: list[Token], candidate: Candidate) -> str:
    """The candidate's tokens joined ("take a look")."""
    return " ".join(t.text for t in tokens[candidate.start: candidate.stop])


def sentence_bounds(tokens: list[Token], candidate: Candidate) -> tuple[int, int]:
    """[first, stop) of the tokens of the candidate's sentence."""
    first = candidate.start
    while first > 0 and not tokens[first - 1].sentence_end:
        first -= 1
    stop = candidate.stop
    while stop < len(tokens) and not tokens[stop - 1].sentence_end:
        stop += 1
    return first, stop


def decidable(tokens: list[Token], candidate: Candidate) -> bool:
    """Whether the words after the candidate that its decision reads have all arrived (for "thanks to", the whole
    sentence: a main clause after a comma makes it causal)."""
    _, stop = sentence_bounds(tokens, candidate)
    whole = tokens[candidate.start].text == "thanks" and candidate.stop < stop and tokens[candidate.stop].text == "to"
    if tokens[candidate.stop - 1].sentence_end and rule(tokens, candidate) is not None:
        return True  # the phrase ends its sentence: the rules read nothing after it ("Hooray!" at once)
    return tokens[stop - 1].sentence_end or not whole and stop - candidate.stop >= AFTER_TOKENS


def clause_start(tokens: list[Token], candidate: Candidate, first: int) -> bool:
    """The candidate opens its sentence or a clause (after punctuation, or after "and", "so", "oh" … there), or
    follows an addressee that opens its sentence ("Everyone come up", "Please come through")."""
    k = candidate.start
    while k > first and tokens[k - 1].text in OPENERS:
        k -= 1
    vocative = candidate.start - first == 1 and tokens[first].text in ADDRESSEES  # "Everyone come up", "Please …"
    return k == first or tokens[k - 1].clause_end or vocative


def rule(tokens: list[Token], candidate: Candidate) -> str | None:
    """"none" where the grammar rules a speech act out, the intent of an interjection standing alone at the start of
    a clause ("Hooray!", "and goodbye!"), else None (the classifier decides)."""
    first, stop = sentence_bounds(tokens, candidate)
    words = [t.text for t in tokens[candidate.start: candidate.stop]]
    after = tokens[candidate.stop].text if candidate.stop < stop else ""
    hyphenated = tokens[candidate.stop - 1].hyphen or (candidate.start > first and tokens[candidate.start - 1].hyphen)
    joined = not tokens[candidate.stop - 1].clause_end
    reads_on = joined or tokens[candidate.stop - 1].paused  # a pause is no comma to grammar: "Thanks (165 ms) to the"
    mentioned = reads_on and after in BE and "presenting" not in candidate.intents  # "come on is what he said"
    phrasal = words == ["come", "on"] and reads_on and after in COME_ON_PLACES  # "come on time", "come on stage"
    crowd = words == ["cheers"] and reads_on and after not in ("for", "to")  # "cheers from the crowd"
    if hyphenated or reported(tokens, candidate, first) or mentioned or phrasal or crowd:
        return "none"
    if words[0] in ("thanks", "thank") and reads_on and (after in NOT_THANKS or causal_thanks(tokens, candidate, stop)):
        return "none"
    if quoted(tokens, candidate, stop) or not_the_act(tokens, candidate, first, stop):
        return "none"
    if named(tokens, candidate, first, stop):
        return "none"
    placed = placed_act(tokens, candidate, first, stop)
    if placed is not None:
        return placed
    interjection = not joined and len(candidate.intents) == 1 and candidate.intents[0] != "presenting"
    if interjection and clause_start(tokens, candidate, first):  # "Hooray!", "Thank you, and goodbye!"
        return candidate.intents[0]
    return None


def placed_act(tokens: list[Token], candidate: Candidate, first: int, stop: int) -> str | None:
    """Where the phrasebook says a phrase can be its act (:func:`gesturecast.realtime.gestures.phrasebook.placement`):
    "none" where an "alone" / "exclaimed" / "opening" phrase stands elsewhere ("Morning traffic", "a brilliant
    idea", "Later, the rook", "a goodnight kiss", "come up with a plan"), its intent where an "alone" / "exclaimed"
    phrase stands alone or a "whole" one opens a clause ("Brilliant!", "Yes!", "Hip hip hooray for …"), else None."""
    place = placement(phrase_of(tokens, candidate))
    if place is None:
        return None
    opening = clause_start(tokens, candidate, first)
    last = tokens[candidate.stop - 1]
    after = tokens[candidate.stop] if candidate.stop < stop else None
    addressee = after is not None and after.text in ADDRESSEES and (after.clause_end or candidate.stop + 1 == stop)
    alone = last.clause_end or candidate.stop == stop
    excluded = after is not None and after.text in NOT_AFTER.get(phrase_of(tokens, candidate), ())
    if place == "whole":
        return candidate.intents[0] if opening else None
    if place == "opening":
        return None if opening and not excluded else "none"
    stands = alone or addressee if place == "alone" else last.exclaimed or addressee
    return candidate.intents[0] if opening and stands else "none"


def quoted(tokens: list[Token], candidate: Candidate, stop: int) -> bool:
    """"Come on, she thought" / "Have a nice day, the sign in the window says" / "Goodbye, sun, said the boy": the
    phrase ends a clause, and one of the next :data:`CLAUSES_AFTER_QUOTE` clauses is an attribution
    (:func:`attribution`): the words are quoted, not said to the listener."""
    end = next((k for k in range(candidate.stop - 1, stop) if tokens[k].clause_end), stop - 1)
    for _ in range(CLAUSES_AFTER_QUOTE):
        if tokens[end].sentence_end or end + 1 >= stop:
            return False
        clause_stop = next((k + 1 for k in range(end + 1, stop) if tokens[k].clause_end), stop)
        if attribution([t.text for t in tokens[end + 1: clause_stop]]):
            return True
        end = clause_stop - 1
    return False


def attribution(clause: list[str]) -> bool:
    """A speaker and a verb of saying: not opened by a conjunction or a preposition ("I/we/you" only before a verb
    in the past or one said to oneself: "we tell ourselves"), the verb not inside a relative clause, and either right
    after a short speaker, in a clause of at most :data:`ATTRIBUTION_CLAUSE` words, or closing one."""
    if not clause or clause[0] in NOT_ATTRIBUTION:
        return False
    verbs = [k for k, word in enumerate(clause) if word in ATTRIBUTION]
    if not verbs or RELATIVES & set(clause[: verbs[0]]):
        return False
    past = clause[verbs[0]].endswith("ed") or clause[verbs[0]] in PAST_SAYING
    to_self = REFLEXIVE_SELF & set(clause[verbs[0] + 1: verbs[0] + 2])  # "Come on, we tell ourselves"
    if clause[0] in FIRST_PERSON and not (past or to_self):
        return False
    closing = verbs[-1] == len(clause) - 1 and len(clause) <= ATTRIBUTION_CLOSING
    return verbs[0] <= SPEAKER_WORDS or len(clause) <= ATTRIBUTION_CLAUSE or closing


def reported(tokens: list[Token], candidate: Candidate, first: int) -> bool:
    """"He said hello", "she shouted goodbye", "they told us goodbye": a verb of saying (or waving) before the
    phrase, directly or before an object pronoun, reports someone else's act; the speaker's own ("I want to say
    thank you", "let me wish you a good night", :func:`performed`) does not."""
    before = [t.text for t in tokens[max(first, candidate.start - 2): candidate.start]]
    if not before:
        return False
    verb = candidate.start - 1 if before[-1] in REPORTING else candidate.start - 2 if (
        len(before) == 2 and before[0] in REPORTING and before[1] in OBJECTS | {"her", "it"}) else None
    return verb is not None and not performed(tokens, verb, first)


def performed(tokens: list[Token], verb: int, first: int) -> bool:
    """The verb at ``verb`` is the speaker's own performative ("I want to say", "we'd like to wish", "let me
    say"): a base form whose clause, from its start, holds only :data:`PERFORMATIVE_LEAD` words, one of them "I",
    "we" or "let"."""
    if tokens[verb].text not in PERFORMATIVE_VERBS:
        return False
    start = verb
    while start > first and not tokens[start - 1].clause_end:
        start -= 1
    lead = [t.text for t in tokens[start: verb]]
    return bool(SPEAKERS & set(lead)) and all(word in PERFORMATIVE_LEAD for word in lead)


def not_the_act(tokens: list[Token], candidate: Candidate, first: int, stop: int) -> bool:
    """What follows makes the phrase ordinary English: "take care of the maps" / "when you cross" (not a farewell,
    unless "of yourself"), "meet me at the station" (an arrangement, not an introduction), "here we have to" (an
    obligation), "this is why" / "here is where" / "this is not" (an explanation), "look at any map" (nothing to
    point at), "look at the map before you leave" (advice: a subordinate clause in the same clause), "this is Sam
    from customer support" (a caller names themself)."""
    words = phrase_of(tokens, candidate)
    if tokens[candidate.stop - 1].clause_end or candidate.stop >= stop:
        return False
    after = [t.text for t in tokens[candidate.stop: min(stop, candidate.stop + 3)]] + ["", ""]
    care = words == "take care" and after[0] in CARE_COMPLEMENTS and after[1] not in REFLEXIVES
    arranged = words == "meet" and (after[0] in OBJECTS or after[0] == "her" and after[1] in ARRANGING)
    obliged = words.endswith(" have") and after[0] in ("to", "been", "got", "had")
    explaining = words.split()[-1] in ("is", "are", "here's") and after[0] in EXPLAINING
    looked = after[1:] if words in ("take a look", "have a look") and after[0] == "at" else after
    generic = words in ("look at", "take a look", "have a look", "check out") and looked[0] in GENERIC
    clause = next((k + 1 for k in range(candidate.stop, stop) if tokens[k].clause_end), stop)
    advice = words in ("look at", "take a look", "have a look") and any(
        t.text in ADVICE for t in tokens[candidate.stop: clause])
    caller = words == "this is" and after[0] not in DETERMINERS and after[1] in CALLERS  # "this is Sam from support"
    return care or arranged or obliged or explaining or generic or advice or caller


def named(tokens: list[Token], candidate: Candidate, first: int, stop: int) -> bool:
    """The phrase is named, not said: it opens its sentence as the subject of "is" / "was" … at most
    :data:`SUBJECT_WORDS` words on, with no subject of the verb's own between ("See you in court was written",
    "Come on in was painted", "Hello and goodbye were …"), or the clause after it (or after a short address) opens
    with that verb and a determiner ("Hello, stranger, is the first line"). Never in a question ("Hello, is the
    manager in?"), nor for a presenting phrase ("On your left is the market") but a whole one ("Allow me to
    introduce is how every toast began")."""
    introduced = "presenting" in candidate.intents and placement(phrase_of(tokens, candidate)) != "whole"
    if candidate.start != first or introduced or tokens[stop - 1].question:
        return False
    if not tokens[candidate.stop - 1].clause_end:
        if candidate.stop < stop and tokens[candidate.stop].text in DETERMINERS:
            return False  # a new subject: "Hooray the snow is here" as a recogniser may write it
        for token in tokens[candidate.stop: min(stop, candidate.stop + SUBJECT_WORDS + 1)]:
            if token.text in SUBJECT_BE:
                return True
            if token.text in OWN_SUBJECTS or token.clause_end:
                return False
        return False
    start = candidate.stop
    for _ in range(2):  # the clause right after the phrase, or the one after a short address
        if start + 1 >= stop:
            return False
        if tokens[start].text in SUBJECT_BE and tokens[start + 1].text in NAMED:
            return True
        clause_stop = next((k + 1 for k in range(start, stop) if tokens[k].clause_end), stop)
        if clause_stop - start > SPEAKER_WORDS:
            return False
        start = clause_stop
    return False


def causal_thanks(tokens: list[Token], candidate: Candidate, stop: int) -> bool:
    """"Thanks to the rain" / "thanks to careful planning, the bridge opened" / "thanks largely to the manager":
    "thanks (+ a degree) to" followed by a determiner, or by a phrase that a comma closes before a main clause (not
    one opened by "and")."""
    rest = [t for t in tokens[candidate.stop: stop]]
    if rest and rest[0].text in DEGREES and not rest[0].clause_end:  # "thanks largely to the new manager"
        rest = rest[1:]
    if [t.text for t in tokens[candidate.start: candidate.stop]] != ["thanks"] or not rest or rest[0].text != "to":
        return False
    if len(rest) > 1 and rest[1].text in CAUSAL_AFTER:
        return True
    comma = next((k for k, t in enumerate(rest[:-1]) if t.clause_end), None)
    return comma is not None and len(rest) - comma - 1 >= MAIN_CLAUSE_TOKENS and rest[comma + 1].text != "and"


def addressed(tokens: list[Token], candidate: Candidate, since: int | None) -> bool:
    """Whether a presenting phrase presents: narration says "this is the third day", "these are the coldest
    nights", "over there, in a lab in Vienna" as often as a guide says "this is our new coffee machine". A phrase of
    :data:`DEICTIC` presents only within :data:`ADDRESS_SENTENCES` sentences after another act (a greeting, a
    thank-you, a call, a presentation: ``since`` sentence ends ago, None for none), or before "this" / "these" /
    "your" ("look at this", "here is your key"); the other presenting phrases ("meet", "let me show you", "on your
    left") always may."""
    _, stop = sentence_bounds(tokens, candidate)
    words = phrase_of(tokens, candidate)
    if words not in DEICTIC or since is not None and since <= ADDRESS_SENTENCES:
        return True
    after = [t.text for t in tokens[candidate.stop: stop]] + [""]
    shown = after[1] if words in ("take a look", "have a look") and after[0] == "at" else after[0]
    return not tokens[candidate.stop - 1].sentence_end and shown in POINTING


def opens_talk(tokens: list[Token], candidate: Candidate, intent: str) -> bool:
    """Whether the decided ``intent`` starts (or prolongs) a talk (:func:`addressed`): any act but a deictic
    phrase's presenting."""
    return intent != "none" and phrase_of(tokens, candidate) not in DEICTIC


class Embedder:
    """Text → (256,) unit float32 vectors of the packaged wordllama model; "" → zeros."""

    def __init__(self) -> None:
        from gesturecast.models.generator.style_text import load_wordllama

        self.model = load_wordllama()
        self.dim = int(self.model.embed(["a"], norm=True).shape[1])

    def __call__(self, texts: list[str]) -> np.ndarray:
        """(n,) texts → (n, 256)."""
        out = np.zeros((len(texts), self.dim), np.float32)
        filled = [i for i, text in enumerate(texts) if text]
        if filled:
            out[filled] = self.model.embed([texts[i] for i in filled], norm=True)
        return out


def context_texts(tokens: list[Token], words: list[str], candidate: Candidate) -> tuple[str, ...]:
    """(window, before, after, the word before, the word after, the head word after) texts of a candidate, from the
    transcript words (punctuation kept), inside its sentence ("" where there is none). The head word is the first
    after the phrase that is not a determiner ("this is the *part*" / "this is the *kitchen*"; the word after is
    "the" in both)."""
    first, stop = sentence_bounds(tokens, candidate)

    def text(a: int, b: int) -> str:
        indices = dict.fromkeys(t.word for t in tokens[max(a, first): min(b, stop)])
        return " ".join(words[i] for i in indices)

    window = text(candidate.start - WINDOW_TOKENS, candidate.stop + WINDOW_TOKENS)
    before = text(candidate.start - BEFORE_TOKENS, candidate.start) if candidate.start > first else ""
    after = text(candidate.stop, candidate.stop + AFTER_TOKENS) if candidate.stop < stop else ""
    previous = tokens[candidate.start - 1].text if candidate.start > first else ""
    following = tokens[candidate.stop].text if candidate.stop < stop else ""
    head = next((t.text for t in tokens[candidate.stop: stop] if t.text not in DETERMINERS), "")
    return window, before, after, previous, following, head


def shape_features(tokens: list[Token], candidate: Candidate) -> np.ndarray:
    """(6 + 6,) where the candidate stands and the intents it can open."""
    first, stop = sentence_bounds(tokens, candidate)
    last = tokens[candidate.stop - 1]
    flags = [candidate.start == first, clause_start(tokens, candidate, first), last.clause_end, last.sentence_end,
             candidate.stop == stop, candidate.stop - candidate.start > 1]
    intents = [intent in candidate.intents for intent in INTENT_GESTURES]
    return np.array(flags + intents, np.float32)


def features(embed: Embedder, tokens: list[Token], words: list[str], found: list[Candidate]) -> np.ndarray:
    """(n, 6·256 + 12) classifier inputs of the candidates ``found``: the embeddings of :func:`context_texts`
    (the single words next to the phrase tell a function word or an addressee from a noun: "welcome *to*" /
    "welcome *news*") and :func:`shape_features`."""
    if not found:
        return np.zeros((0, CONTEXTS * embed.dim + 12), np.float32)
    texts = [context_texts(tokens, words, c) for c in found]
    parts = [embed([t[k] for t in texts]) for k in range(CONTEXTS)]  # CONTEXTS × (n, 256)
    return np.concatenate(parts + [np.stack([shape_features(tokens, c) for c in found])], axis=1)


@dataclass(frozen=True)
class SpeechActModel:
    """Softmax regression: logits = x @ weights + bias over :data:`CLASSES`."""

    weights: np.ndarray  # (F, len(CLASSES))
    bias: np.ndarray  # (len(CLASSES),)

    def save(self, path: Path) -> None:
        np.savez(path, weights=self.weights.astype(np.float32), bias=self.bias.astype(np.float32),
                 classes=np.asarray(CLASSES), feature_version=FEATURE_VERSION)

    @classmethod
    def load(cls, path: Path) -> SpeechActModel:
        try:
            with np.load(path) as data:
                if tuple(data["classes"]) != CLASSES or int(data["feature_version"]) != FEATURE_VERSION:
                    raise UserError(f"{path}: speech-act weights of another version; retrain with "
                                    "`gesturecast gestures train-acts`")
                return cls(data["weights"], data["bias"])
        except (OSError, KeyError, ValueError) as error:
            raise UserError(f"{path}: cannot read the speech-act weights ({error})") from None

    def probabilities(self, x: np.ndarray) -> np.ndarray:
        """(n, F) → (n, len(CLASSES))."""
        logits = x @ self.weights + self.bias
        logits -= logits.max(axis=1, keepdims=True)
        exp = np.exp(logits)
        return exp / exp.sum(axis=1, keepdims=True)


def default_weights() -> Path:
    from importlib import resources

    return Path(str(resources.files("gesturecast.models"))) / "weights" / "gestures" / "speech_acts.npz"


class SpeechActClassifier:
    """Candidates → intents ("none" or one of :data:`INTENT_GESTURES`): rules first, then the model."""

    def __init__(self, model: SpeechActModel | None = None, embed: Embedder | None = None) -> None:
        self.model = model or SpeechActModel.load(default_weights())
        self.embed = embed or Embedder()

    def decide(self, tokens: list[Token], words: list[str], found: list[Candidate], since: int | None = None
               ) -> list[str]:
        """One intent per candidate (the likeliest of "none" and the intents its phrase can open); a deictic
        presenting phrase only where the speaker is addressing someone (:func:`addressed`), which a deictic phrase's
        own presenting does not prolong (one false act opens at most :data:`ADDRESS_SENTENCES` sentences). ``since``:
        sentence ends between the last act decided before ``tokens`` and their start (None: no act yet)."""
        ruled = [rule(tokens, c) for c in found]
        open_ = [c for c, r in zip(found, ruled, strict=True) if r is None]
        probabilities = iter(self.model.probabilities(features(self.embed, tokens, words, open_)))
        sentence = np.cumsum([0] + [t.sentence_end for t in tokens])  # (len(tokens) + 1,) sentence of each token
        last = None if since is None else -since  # the sentence of the last act, counted like ``sentence``
        decided = []
        for candidate, ruling in zip(found, ruled, strict=True):
            here = int(sentence[candidate.start])
            since_act = None if last is None else here - last
            intent = ruling or self._likeliest(tokens, candidate, next(probabilities), since_act)
            if intent == "presenting" and not addressed(tokens, candidate, since_act):
                intent = "none"
            last = here if opens_talk(tokens, candidate, intent) else last
            decided.append(intent)
        return decided

    @staticmethod
    def _likeliest(tokens: list[Token], candidate: Candidate, p: np.ndarray, since_act: int | None) -> str:
        """The likeliest of "none" and the candidate's intents under the (len(CLASSES),) probabilities ``p``; in a
        talk (another act at most :data:`ADDRESS_SENTENCES` sentences back) a deictic phrase presents from
        :data:`ADDRESSED_PRESENTING` on: the model is fitted on text where "this is the …" is as often narration."""
        intent = max(("none", *candidate.intents), key=lambda name: p[CLASSES.index(name)])
        talk = since_act is not None and since_act <= ADDRESS_SENTENCES
        deictic = phrase_of(tokens, candidate) in DEICTIC
        leans = p[CLASSES.index("presenting")] >= ADDRESSED_PRESENTING
        return "presenting" if intent == "none" and talk and deictic and leans else intent
