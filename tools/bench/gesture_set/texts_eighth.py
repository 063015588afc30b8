"""The eighth held-out text set of ``gesturecast bench gestures`` (``--stories eighth``): written after the seventh
set's run and before a sentence encoder was tried for candidates without a list, committed on its own before any
change to the rules, the phrases, the training sentences or the classifier, and run once at the end. Never used to
write rules, phrases or to train the classifier.

The conventions are those of :mod:`gesturecast.tools.bench.gesture_set.texts`. Eight cued stories of everyday talk
(a dentist's reception, a bakery counter, a campsite, a wedding toast, a bike repair shop, a choir rehearsal, a
library story time, a youth football team) with 40 intended cues (greeting 7, thanks 7, farewell 7, celebration 7,
presenting 6, calling 6), most in phrasings no earlier set and no phrasebook family holds ("Lovely to see you",
"Look who's here", "Long time no see", "You're too kind", "Props to", "Happy trails", "Godspeed", "Adios", "Whoopee",
"Booyah", "Back of the net", "Have a squiz at", "Over yonder", "Pop through", "Scoot in closer", "Bunch up"), a few
that a listed phrase only resembles ("Here's to the happy couple!" is a toast), and about 4.5 minutes of narration
(74 sentences) in ten voices none of the other sets uses: a weather forecast, a recipe, a football match report, a
history lecture, a car manual, a bedtime story, a gardening column, a science news item, a railway engineering
notice and a court report. The narration has this / these / here / there / look / welcome / thanks to / take care /
see you / come on / cheers / bye / hello / morning / goodnight / lovely in ordinary use, and clause openings that
look like acts and are not ("Lovely weather is on the way", "Happy hour prices", "Look who won the seat",
"Well played cards", "Pop the lid", "Godspeed was the name of the ship").
"""

from __future__ import annotations

CUED_STORIES_EIGHTH: dict[str, tuple[str, ...]] = {
    "dentist-reception": (
        "[wave]Lovely to see you, Mr Okafor.",
        "[guide]Have a squiz at this leaflet about flossing while you wait.",
        "Doctor Reyes is running about ten minutes behind.",
        "[call]Pop through to room two whenever you're ready.",
        "No fillings this time, [raise-both]well played!",
        "[bow]You're too kind, fitting me in at such short notice.",
    ),
    "bakery-counter": (
        "[wave]Look who's here, my favourite customer!",
        "[guide]Fresh out of the oven, the cinnamon knots.",
        "[raise-both]Whoopee, the sourdough finally rose!",
        "[bow]Eternally grateful for the recipe, Maria.",
        "[bye]Toodles, enjoy your loaf!",
    ),
    "campsite": (
        "[wave]Salutations, campers, and welcome to Pine Hollow.",
        "[call]Everybody to the fire pit for the safety talk.",
        "[guide]Over yonder is the shower block, past the big oak.",
        "[raise-both]Booyah, the tent is up in under ten minutes!",
        "Marshmallows are in the blue crate by the door.",
        "[bye]Happy trails, and leave nothing but footprints.",
    ),
    "wedding-toast": (
        "[call]Scoot in closer, everyone at the back.",
        "[guide]May I direct your attention to the cake table.",
        "[bow]We owe you big time, Mum and Dad, for all of this.",
        "[raise-both]Here's to the happy couple!",
        "[bye]Godspeed on the honeymoon, you two.",
    ),
    "bike-repair-shop": (
        "[wave]How do, folks, what seems to be the trouble?",
        "[call]Wheel it over to me and I'll take a look.",
        "[guide]Cop a load of this chain, it's completely worn through.",
        "[bow]Appreciate you bringing it in before it snapped.",
        "[bye]Ride safe out there, and check those brakes.",
    ),
    "choir-rehearsal": (
        "[wave]Long time no see, Gerald, we missed your bass line.",
        "[call]Sopranos, shuffle forward a bit so I can hear you.",
        "The second verse is where we keep rushing.",
        "[raise-both]Bravissimo, that was the best run yet!",
        "[bow]Gratitude to the altos for learning their parts at home.",
        "[bye]Off you pop, and rest those voices.",
    ),
    "library-story-time": (
        "[wave]Bonjour, little readers!",
        "[call]Bunch up on the carpet so everyone can see.",
        "[guide]Right in front of you is Barnaby, the sleepiest bear in the woods.",
        "[bow]We're so lucky to have you, volunteers.",
        "[bye]Until tomorrow, bookworms!",
    ),
    "football-team": (
        "[wave]Top of the morning, lads!",
        "[raise-both]Back of the net, Tomas, what a strike!",
        "[raise-both]Champions, the lot of you!",
        "[bow]Props to the parents for all the early lifts.",
        "[bye]Adios, amigos, same time next week.",
    ),
}

NARRATION_EIGHTH: tuple[str, ...] = (
    # a weather forecast
    "Lovely weather is on the way for most of the country this weekend.",
    "This morning there will be patchy fog in the valleys.",
    "Here in the east the cloud will break up by lunchtime.",
    "There is a chance of thunder over the hills later on.",
    "Take care on the roads tonight, as temperatures dip below freezing.",
    "Thanks to a ridge of high pressure, the week ahead looks settled.",
    "Look out for frost in sheltered spots by Thursday.",
    "Goodnight temperatures will hover just above zero in the cities.",
    # a recipe
    "Pop the lid on the pan and let the onions sweat for five minutes.",
    "This is the point where most people add too much salt.",
    "Here you want the butter foaming but not brown.",
    "Welcome additions include capers, olives or a handful of herbs.",
    "Come back to the sauce after ten minutes and give it a stir.",
    "These are best eaten warm, straight from the tray.",
    "Cheers to whoever invented the silicone spatula, my grandmother used to say.",
    "Lovely and crisp is what you are looking for on the skin.",
    # a football match report
    "Well played cards from the referee kept the first half under control.",
    "Look who won it, then: the side that nobody tipped in August.",
    "There were three shots on target in the whole first half.",
    "This was the club's first away win since the spring.",
    "Back of the net stories sell papers, but the defence won this game.",
    "Hello to the promotion places, then, for the first time in a decade.",
    "The winger came on for the last twenty minutes and changed everything.",
    "Thanks to a late penalty, the visitors took all three points.",
    # a history lecture
    "This is the period historians call the long eighteenth century.",
    "There were riots in the port towns every winter.",
    "Godspeed was the name of the ship that carried the first settlers.",
    "Look at the trade figures and the story becomes clear.",
    "Here the sources fall silent for almost twenty years.",
    "Welcome as the peace was, it did not last.",
    "See you in the colonies was a common farewell in the letters of the time.",
    "These are questions we will come back to next week.",
    # a car manual
    "This is the fuse box, located behind the glove compartment.",
    "Here you will find the jack and the spare wheel.",
    "Take care not to overfill the washer fluid reservoir.",
    "There is a warning light for low tyre pressure on the dashboard.",
    "Look at the tread depth indicator every few months.",
    "Come to a complete stop before shifting into reverse.",
    "Pop the bonnet by pulling the lever under the steering column.",
    "Check the oil level with the engine cold and on level ground.",
    # a bedtime story
    "Once upon a time there was a fox who could not sleep.",
    "Goodnight, moon, said the little fox, but the moon did not answer.",
    "Hello, said a voice from the bottom of the well.",
    "This is the deepest well in the whole forest, said the frog.",
    "Come down and see, the frog called, but the fox was far too scared.",
    "Lovely dreams came at last, full of stars and fishing boats.",
    "Bye the time the sun rose, the fox was fast asleep.",
    # a gardening column
    "Happy hour for slugs is just after dusk on a damp evening.",
    "This is the month to sow broad beans for an early crop.",
    "There are few things more cheering than the first snowdrop.",
    "Here in the north we plant our potatoes a little later.",
    "Look for sturdy seedlings with dark green leaves.",
    "Welcome rain last week has brought the lawns back to life.",
    "Thanks to the mild autumn, the dahlias are still flowering.",
    "Cheers, the old gardener said to me once, are the best fertiliser.",
    # a science news item
    "Researchers say this is the closest look yet at a distant comet.",
    "There is water ice beneath the surface, the team believes.",
    "Here the data suggest a much younger age than expected.",
    "See you in five thousand years, one astronomer joked of its orbit.",
    "Look at the tail and you can see it pointing away from the sun.",
    "Take care when comparing the figures, the authors warn.",
    "Congratulations poured in from space agencies around the world.",
    # a railway engineering notice
    "Morning services between the two towns will be replaced by buses.",
    "This is to allow the replacement of a bridge near the station.",
    "There will be no trains on Sunday after eight in the evening.",
    "Here is a summary of the changes for each day of the week.",
    "Come rain or shine, the work is due to finish by the end of May.",
    "Thanks to the new signalling, journeys will be quicker once the work is done.",
    # a court report
    "See you in court, the defendant had written in a text message.",
    "This is a case about trust, the prosecutor told the jury.",
    "There was no evidence that the money had been moved abroad.",
    "Here the judge paused to remind the jury of the timeline.",
    "Welcome news for the family came just before five o'clock.",
    "Look at the dates on the invoices, the barrister urged.",
)
