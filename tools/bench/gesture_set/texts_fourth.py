"""The fourth held-out text set of ``gesturecast bench gestures`` (``--stories fourth``): written after the fifth
phrase revision and the performative "I want to say thank you" rule, and run once on them, with no change after it.
Never used to write rules or to train the classifier.

The conventions are those of :mod:`gesturecast.tools.bench.gesture_set.texts`. Six cued stories in situations the
other sets lack (a yoga class, a train, a charity auction, a dentist's desk, a half-time talk, a leaving party) and
4 minutes of narration in eight voices: a gardening column, a science explainer, a film review, a weather
forecast, a biography, a court report, a hiking guide and a school newsletter.
"""

from __future__ import annotations

CUED_STORIES_FOURTH: dict[str, tuple[str, ...]] = {
    "yoga-class": (
        "[wave]Good morning, everybody, and [wave]welcome to the mat.",
        "[guide]Here is the block you will need for the first pose.",
        "Breathe in slowly and lift both arms.",
        "[raise-both]Well done, that was the hardest sequence!",
        "[bow]Thank you for practising with me, and [bye]see you on Thursday.",
    ),
    "night-train": (
        "[wave]Hello, ladies and gentlemen.",
        "The restaurant car is open until ten tonight.",
        "[guide]On your left you can see the lights of the harbour.",
        "[bow]Thanks for your patience during the delay.",
        "[bye]Good night, and [bye]sleep well.",
    ),
    "charity-auction": (
        "[wave]Hi, everyone, [bow]thank you for coming out tonight.",
        "[guide]Take a look at our first lot, a signed guitar.",
        "[call]Come closer, the bidding starts at fifty.",
        "[raise-both]Congratulations, sold to the lady in blue!",
        "[bow]Cheers to all of our volunteers.",
    ),
    "dentist-desk": (
        "[wave]Hiya, you must be Mister Patel.",
        "The doctor is running ten minutes late.",
        "[guide]These are the forms for new patients.",
        "[bow]Thanks a lot, and [bye]have a lovely afternoon.",
    ),
    "half-time": (
        "[call]Gather round, lads.",
        "[raise-both]Bravo, that first goal was perfect!",
        "[guide]Look at the board, this is where we lose the ball.",
        "[call]Come on, one more goal and it's ours!",
    ),
    "leaving-party": (
        "[wave]Hey, [wave]welcome, grab a drink.",
        "I want to say [bow]thank you to Rosa for eleven wonderful years.",
        "[guide]Meet her replacement, Tomasz, who starts on Monday.",
        "[raise-both]Hooray for Rosa!",
        "[bye]Goodbye, Rosa, and [bye]take care of yourself.",
    ),
}

NARRATION_FOURTH: tuple[str, ...] = (
    # a gardening column
    "This is the month when the roses need the most water.",
    "There is no point in pruning before the frost has passed.",
    "Thanks to a mild winter, the slugs are everywhere this year.",
    "Here in the south, tomatoes can go outside in early May.",
    "Take care not to drown the seedlings on a cold night.",
    "These are the plants that bees like best: lavender, thyme and borage.",
    "Welcome visitors to any garden, ladybirds eat the greenfly.",
    "Look at the underside of the leaves if you suspect mites.",
    "Come autumn, the whole border turns a deep red.",
    "Cheers from the neighbours greeted my first giant pumpkin.",
    # a science explainer
    "This is a question physicists argued about for a century.",
    "There are two ways light can behave, as a wave or as a particle.",
    "Here the experiment gets strange.",
    "These are the results that surprised everyone in the lab.",
    "When the detector is switched on, the pattern disappears.",
    "The two beams meet on a screen at the far end of the room.",
    "This is, to put it simply, still a mystery.",
    "Thanks to better lasers, the test can now be done in a classroom.",
    "Over there, in a lab in Vienna, the same effect was seen with large molecules.",
    "Say goodbye to common sense, one textbook warns its readers.",
    # a film review
    "This is the director's fourth film, and easily her best.",
    "There is a long scene in a kitchen that nobody will forget.",
    "The hero meets his brother again after twenty years.",
    "Hello, stranger, is the first line, and it lands perfectly.",
    "These are actors at the top of their game.",
    "The lights come on in the cinema far too quickly at the end.",
    "Here the film slows down, perhaps too much.",
    "Thanks to the music, the last twenty minutes fly by.",
    "See you in the next life, the brother says, and walks away.",
    "I can see you loving it or hating it, with nothing in between.",
    # a weather forecast
    "This is a slow moving front, so the rain will last.",
    "There will be sunny spells in the east by the afternoon.",
    "Here in the city, temperatures stay mild overnight.",
    "Take care on the roads, the police are asking drivers.",
    "Thanks to a high to the north, the weekend looks dry.",
    "The frost will come on quickly once the skies clear.",
    "These are the coldest nights of the year so far.",
    "Over there on the coast, gusts could reach sixty miles an hour.",
    # a biography
    "This is the house where she was born, in eighteen ninety one.",
    "There were nine children, and she was the youngest.",
    "Her father would wish every customer a good day at the shop door.",
    "Here she learned to read from old newspapers.",
    "She said goodbye to her family at sixteen and took the train south.",
    "Welcome or not, she stayed in the capital for forty years.",
    "These are the years of her greatest work.",
    "Meet me in Paris, a friend wrote, and she went.",
    "Thanks to that letter, she met the publisher who changed her life.",
    "This is a life that deserves a longer book.",
    # a court report
    "This is the third day of the trial.",
    "There was a long silence when the witness was asked to come forward.",
    "Thanks to the new evidence, the defence asked for a delay.",
    "The judge told the jury to take care with the phone records.",
    "Here the case turns on a single email.",
    "These are serious charges, the prosecutor reminded the court.",
    "The two lawyers will meet the judge again on Monday.",
    "Over there, the defendant's family sat in silence.",
    "Hello was the only word the defendant spoke all day.",
    "See you in court was written on the note found in his car.",
    # a hiking guide
    "This is a walk for a clear day, not for fog.",
    "There is a spring halfway up where you can fill your bottle.",
    "Here the path splits, and the left fork is steeper.",
    "Look at the map before you leave the car park.",
    "Thanks to the new bridge, the river crossing is safe all year.",
    "Take care where the path runs along the cliff edge.",
    "These are the best views in the whole national park.",
    "Come on foot if you can, because parking is limited.",
    "Over there, beyond the second ridge, lies the old mining village.",
    "Bye laws forbid camping anywhere outside the marked sites.",
    # a school newsletter
    "This is a busy term for the whole school.",
    "There are still places on the trip to the science museum.",
    "Thanks to the parents' association, the library has new books.",
    "Here is a reminder that uniforms must be labelled.",
    "The chess club was told well done by the mayor after winning the county trophy.",
    "Congratulations cards from other schools filled the staff room.",
    "We will welcome three new teachers in September.",
    "The head teacher will meet new families in the hall on Friday.",
    "Have a good holiday, the last line of the newsletter reads.",
)
