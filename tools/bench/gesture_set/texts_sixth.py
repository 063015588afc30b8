"""The sixth held-out text set of ``gesturecast bench gestures`` (``--stories sixth``): written after the fifth set's
run and before the phrasebook revision (the candidate phrases per act from general English), committed on its own
before any change to the rules, the phrases, the training sentences or the classifier, and run once at the end.
Never used to write rules, phrases or to train the classifier.

The conventions are those of :mod:`gesturecast.tools.bench.gesture_set.texts`. Eight cued stories of everyday talk
(a bike shop, a breakfast radio show, a family video call, a classroom, a walking tour, a house party, a game stream,
a dental receptionist) with 41 intended cues in phrasings no earlier set uses, and about 4.5 minutes of narration
(74 sentences) in nine voices none of the other sets uses: a wildlife documentary, a car maintenance manual, a
memoir, a stock market report, a chess commentary, an astronomy guide, a fairy tale, a job-advice column and a
nurse's night-shift diary, with this / these / here / there / look at / welcome / thanks to / take care / see you /
come on / cheers / bye / hello / morning / goodnight / brilliant in ordinary use.
"""

from __future__ import annotations

CUED_STORIES_SIXTH: dict[str, tuple[str, ...]] = {
    "bike-shop": (
        "[wave]Afternoon, what can I get for you today?",
        "[guide]Right here we've got the new winter tyres, just in.",
        "They fit most city bikes without any changes.",
        "[raise-both]Fantastic, that's the last pair in your size!",
        "[bow]Ta very much, that's forty pounds exactly.",
        "[bye]Mind how you go now.",
    ),
    "breakfast-radio": (
        "[wave]Rise and shine, early birds, this is Sunrise FM.",
        "[raise-both]Yes! We've hit our fundraising target!",
        "[bow]Huge thanks to everyone who phoned in.",
        "[guide]Joining me in the studio is Tom, our new weather presenter.",
        "[bye]Talk to you tomorrow, same time, same place.",
    ),
    "family-call": (
        "[wave]Hello hello, can you hear me okay, Nan?",
        "[guide]And here she is, little Maya, she's got your nose.",
        "[raise-both]Three cheers for the birthday girl!",
        "[bow]Much obliged for the jumper you knitted.",
        "[bye]Night night, Nan, lots of love.",
    ),
    "classroom": (
        "[wave]Hello again, Year Six, settle down please.",
        "[call]Jamal, step up to the board, please.",
        "[guide]Everyone, eyes on this diagram of the heart.",
        "[raise-both]Way to go, every one of you passed the test!",
        "[bye]Have a good half term, everyone.",
    ),
    "walking-tour": (
        "[wave]Greetings, travellers, I'm Lucia, your guide this morning.",
        "[call]Follow me, folks, and mind the cobbles.",
        "[guide]Up ahead you'll see the oldest bridge in the city.",
        "[guide]Feast your eyes on that view over the river.",
        "[bow]Thank you kindly, you've been a wonderful group.",
    ),
    "house-party": (
        "[wave]Evening, all, you made it!",
        "[call]Get in here, it's freezing out!",
        "[guide]Everybody, this is my flatmate Jo.",
        "[raise-both]Wahey, let's get this party started!",
        "[bow]Cheers for coming, it means a lot.",
        "[bye]Safe home, everyone!",
    ),
    "game-stream": (
        "[wave]Yo chat, what's up!",
        "[raise-both]Let's go, first place!",
        "[bow]Appreciate the sub, Ghost.",
        "[guide]Get a load of this new skin I unlocked.",
        "Alright, I'm out, [bye]peace!",
    ),
    "dental-reception": (
        "[wave]Good day, do you have an appointment?",
        "[guide]This is your visitor badge, clip it to your jacket.",
        "[call]Please come through, the doctor is ready for you.",
        "[bow]Thanks a million for your patience.",
        "[bye]All the best, and mind the wet floor.",
    ),
}

NARRATION_SIXTH: tuple[str, ...] = (
    # a wildlife documentary
    "This is the only place on earth where these frogs still breed.",
    "These are the last hours of daylight before the hunt begins.",
    "Here the river slows and spreads into a shallow marsh.",
    "There, among the reeds, a heron waits without moving.",
    "Look at the way the cub copies its mother's every step.",
    "Thanks to a wet spring, the herd has more calves than usual.",
    "Morning mist hides the valley until the sun climbs over the ridge.",
    "The young male will take care of the nest while the female feeds.",
    # a car maintenance manual
    "This is the most common cause of a flat battery in winter.",
    "These are the bolts that hold the wheel to the hub.",
    "Check the tyre pressure here, on the label inside the driver's door.",
    "There should be a small gap between the pad and the disc.",
    "Take care not to overtighten the oil filter.",
    "Look at the dipstick in good light to judge the colour of the oil.",
    "Thanks to modern sensors, most faults now show on the dashboard.",
    "Come back to this page whenever the warning light comes on.",
    # a memoir
    "Morning was my father's favourite time, before the shop opened.",
    "He would say hello to the milkman as if they were old friends.",
    "This is the kitchen table where I learned to read.",
    "There was always bread on it, and usually a cat.",
    "My mother gave us a goodnight kiss even when we were too old for it.",
    "Cheers went up in the pub across the road whenever the local team scored.",
    "See you in the spring, my uncle wrote on every postcard, and he never came.",
    "These are the things I think of when I smell fresh bread.",
    # a stock market report
    "This is the fourth week in a row that shares have fallen.",
    "These are the weakest numbers since the start of the year.",
    "There was little appetite for risk among investors.",
    "Here the picture is more mixed, with energy stocks holding up well.",
    "Thanks to a strong dollar, exporters had a difficult quarter.",
    "Morning trading was quiet ahead of the bank's announcement.",
    "Analysts say the market could come on strongly if rates are cut.",
    "Look at the bond market and a different story appears.",
    # a chess commentary
    "This is a brilliant idea from the young Norwegian.",
    "These are the positions where one slip decides the game.",
    "Here white could have taken the pawn, but chose to wait.",
    "There is no way back for the black king now.",
    "Look at the knight on the edge of the board, it is doing nothing.",
    "Thanks to that sacrifice, the rook reaches the seventh rank.",
    "Welcome news for the champion, his rival has offered a draw.",
    "Come on, you can almost hear the audience whisper as the clock runs down.",
    # an astronomy guide
    "This is the best month of the year to see the Milky Way.",
    "These are the stars that sailors once used to find north.",
    "Here, low in the east, Jupiter rises just after midnight.",
    "There is a faint smudge below it, a galaxy two million light years away.",
    "Look at it through binoculars and it becomes an oval glow.",
    "Thanks to the new moon, the sky will be darker than usual.",
    "The morning star is not a star at all, but the planet Venus.",
    "Take care with your eyes, and never point a telescope near the sun.",
    # a fairy tale
    "Once there was a miller who had nothing but a mill, a donkey and a cat.",
    "Goodnight, said the cat to the donkey, and curled up by the fire.",
    "Here the road split into three, and each way looked darker than the last.",
    "This is the forest where the king's daughter was lost, said the old woman.",
    "The wolf bade them welcome with a smile that showed all his teeth.",
    "Bye and bye, the youngest son came to a castle made of glass.",
    "Thanks to the cat's cunning, the miller's son became a lord.",
    "And they all lived happily, until the morning the dragon came back.",
    # a job-advice column
    "This is the question I am asked more than any other.",
    "These are the mistakes that cost people interviews.",
    "There is no need to learn your answers by heart.",
    "Here a short pause is better than a rushed reply.",
    "Thanks to video interviews, first impressions now begin with your background.",
    "Take care that your email address sounds professional.",
    "Look at the company's recent news before you go in.",
    "A brilliant cover letter will not save a careless application.",
    "Saying hello to the receptionist costs nothing and is often noticed.",
    # a nurse's night-shift diary
    "This is my third night in a row on the children's ward.",
    "These are the hours when the corridors go quiet.",
    "There was a new admission just after two, a boy with a broken arm.",
    "Here the lights are dimmed at ten so the patients can sleep.",
    "Cheers erupted from the staff room when the pizza arrived.",
    "I said goodnight to the last visitor at nine and locked the side door.",
    "Thanks to the porters, the lifts kept running through the power cut.",
    "See you tomorrow, the day sister called, as I handed over at seven.",
    "Come morning, I could barely keep my eyes open.",
)
