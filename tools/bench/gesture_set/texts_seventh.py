"""The seventh held-out text set of ``gesturecast bench gestures`` (``--stories seventh``): written after the sixth
set's run and before candidates without a list (every clause opening scored by the classifier), committed on its own
before any change to the rules, the phrases, the training sentences or the classifier, and run once at the end.
Never used to write rules, phrases or to train the classifier.

The conventions are those of :mod:`gesturecast.tools.bench.gesture_set.texts`. Eight cued stories of everyday talk
(a hair salon, a ferry crossing, an office leaving do, a pub quiz, a swimming lesson, a farmers' market stall, a
school science fair, a birthday video message) with 40 intended cues (greeting 7, thanks 7, farewell 7, celebration
7, presenting 6, calling 6), most in phrasings the phrasebook does not hold ("Good to see you again", "Ahoy there",
"You're a star", "Look after yourself", "Bon voyage", "Woop woop", "Hats off to", "Happy days", "Voilà", "Huddle
in", "In you hop", "Step right up"), and about 4.5 minutes of narration (74 sentences) in nine voices none of the other
sets uses: a detective novel, a restaurant review, a yoga class, a software release note, a beekeeping guide, the
minutes of a council meeting, a fishing report, a pharmacy leaflet and a sailing logbook. The narration has this /
these / here / there / look at / welcome / thanks to / take care / see you / come on / cheers / bye / hello /
morning / goodnight / brilliant in ordinary use, and many clause openings that look like acts and are not
("Mind the gap", "Follow the footpath", "Good luck was not enough", "Happy customers", "Step two").
"""

from __future__ import annotations

CUED_STORIES_SEVENTH: dict[str, tuple[str, ...]] = {
    "hair-salon": (
        "[wave]Good to see you again, Mrs Patel!",
        "[guide]Have a gander at these colour swatches while the kettle boils.",
        "The copper one would suit your skin tone.",
        "[raise-both]Ooh, gorgeous, you look ten years younger!",
        "[bow]You're a star for waiting so long.",
        "[bye]Look after yourself, and see you in six weeks.",
    ),
    "ferry-crossing": (
        "[wave]Ahoy there, passengers, this is your captain speaking.",
        "[call]Bring the little ones up to the railing, there are dolphins off the bow!",
        "[raise-both]Woop woop, there they go!",
        "[bow]Grateful to you all for sailing with us today.",
        "[bye]Bon voyage, and mind the ramp on your way off.",
    ),
    "office-leaving-do": (
        "[call]Huddle in, folks, so everyone at the back can hear.",
        "[guide]Introducing the woman of the hour, our very own Jen!",
        "Twelve years in accounts, and never once late with the payroll.",
        "[bow]Couldn't have done it without you, Jen, honestly.",
        "[raise-both]Hats off to twelve wonderful years!",
        "[bye]Good luck out there, and don't be a stranger.",
    ),
    "pub-quiz": (
        "[wave]What's up, quiz fans, pens at the ready!",
        "[guide]Up on the screen now is the picture round.",
        "[raise-both]Nice one, table six, you've taken the lead!",
        "[call]Team captains, up to the bar with your answer sheets.",
        "[bye]Laters, everyone, get home safe.",
    ),
    "swimming-lesson": (
        "[wave]Rise and splash, little fishes!",
        "[call]In you hop, one at a time.",
        "[guide]These are your armbands, they go just above the elbow.",
        "[raise-both]Superstar, Ava, a whole width on your own!",
        "[bow]Ever so grateful, mums and dads, for the early starts.",
    ),
    "farmers-market": (
        "[wave]Alright, my love, what can I get you?",
        "[call]Come and have a taste, don't be shy!",
        "[bow]Bless you, that's six pounds fifty.",
        "[raise-both]Happy days, that's me sold out!",
        "[bye]Ta-ra, enjoy the strawberries!",
    ),
    "science-fair": (
        "[wave]Nice to meet you, I'm Priya from class four.",
        "[guide]Voilà, the robot we built this term!",
        "[call]Step right up and press the big green button.",
        "It should draw a circle, if the batteries hold out.",
        "[bow]Appreciate you having a go.",
        "[bye]Enjoy the rest of the fair!",
    ),
    "birthday-video": (
        "[wave]Hey birthday boy, it's Auntie Rose!",
        "[raise-both]Happy fortieth, you old rascal!",
        "[guide]Take a peek at the cake we baked you.",
        "[bow]Thanks for always being there for us.",
        "[bye]Until next summer, big hugs from all of us!",
    ),
}

NARRATION_SEVENTH: tuple[str, ...] = (
    # a detective novel
    "This is the third body found on the towpath since March, the inspector said.",
    "There was mud on the dead man's shoes, but none on the stairs.",
    "Look at the clock, she told herself, it stopped at ten past four.",
    "Good luck was not enough to explain the missing key.",
    "Thanks to the rain, every footprint in the lane had washed away.",
    "Morning came grey and slow over the harbour.",
    "Follow the money, her old sergeant used to say.",
    "See you in the dock, the suspect sneered as they led him away.",
    "Well, that changes everything, Holloway muttered.",
    # a restaurant review
    "This is the kind of place that takes its bread seriously.",
    "These are the best chips I have eaten this year.",
    "Here the menu changes every week with the market.",
    "The welcome at the door was warm, if a little rushed.",
    "Happy customers filled every table by eight o'clock.",
    "Cheers rang out from a birthday party in the corner.",
    "Brilliant as the starters were, the pudding was a let-down.",
    "Save room for the cheese, which comes from a farm up the road.",
    "Nice touches, like warm plates, show real care in the kitchen.",
    # a yoga class
    "Come up slowly onto your knees, one vertebra at a time.",
    "Look at a point on the floor in front of you to keep your balance.",
    "Here we hold the pose for five slow breaths.",
    "Bring your right foot forward between your hands.",
    "Rise onto your toes and reach the arms towards the ceiling.",
    "Take care not to lock the knees in this position.",
    "Step the left foot back into a long lunge.",
    "Now let the arms fall and hang like a rag doll.",
    # a software release note
    "This is a maintenance release with no new features.",
    "These are the changes since version four point two.",
    "Welcome screens no longer appear after every update.",
    "Thanks to a new cache, search results load twice as fast.",
    "Hello messages from the server are now logged at debug level.",
    "Bye-laws and other legal texts now render with proper footnotes.",
    "Great care was taken to keep the old settings working.",
    "Get the latest version from the download page.",
    # a beekeeping guide
    "This is the time of year when colonies start to swarm.",
    "There should be at least five frames of brood in a healthy hive.",
    "Look at the entrance on a warm afternoon to judge how busy the colony is.",
    "Here the queen lays up to two thousand eggs a day.",
    "Smoke the entrance gently before you lift the lid.",
    "Mind the bees on the underside of the crown board.",
    "All the best honey comes from the late summer flow.",
    "Thanks to the mild winter, most colonies came through strong.",
    # the minutes of a council meeting
    "The chair welcomed members and noted apologies from two councillors.",
    "This is the second time the library budget has been cut.",
    "There were questions about the state of the footbridge.",
    "Councillor Ahmed said thanks to the volunteers were long overdue.",
    "Congratulations were sent to the town's youth choir on its award.",
    "See you at the next meeting was the chair's only comment on the matter.",
    "Members agreed to look at the parking charges again in spring.",
    "Step two of the plan is a consultation with local businesses.",
    # a fishing report
    "Morning tides have been kind to shore anglers all week.",
    "Here the bass are feeding close in, just behind the breakers.",
    "There is a good run of mackerel off the harbour wall.",
    "Look at the birds working the water and you will find the fish.",
    "Bye-catch of small cod has been heavy in the nets.",
    "Come on strong with the lure and the wrasse will follow.",
    "Thanks to the settled weather, the boats went out every day.",
    "Take care on the rocks at low water, they are slippery with weed.",
    # a pharmacy leaflet
    "This is a medicine for the short-term relief of hay fever.",
    "These are the common side effects, which usually pass within a day.",
    "Take one tablet each morning with a glass of water.",
    "Keep out of the sight and reach of children.",
    "Stop taking the tablets and see your doctor if a rash appears.",
    "There is no need to take a missed dose.",
    "Ask your pharmacist if you are unsure about anything in this leaflet.",
    "Goodnight tablets that help you sleep should not be taken with this medicine.",
    # a sailing logbook
    "Morning, wind southwest four, sea slight, visibility good.",
    "Here we reefed the main after the squall line passed.",
    "There was a fishing fleet on the horizon all afternoon.",
    "Hello from a passing yacht on the radio, asking for a weather report.",
    "This is the first night at anchor since leaving Falmouth.",
    "Cheers from the crew when the anchor finally held.",
    "Follow the buoyed channel in, the log says, and keep the green marks to starboard.",
    "Goodnight to the watch at midnight, and all quiet until dawn.",
)
