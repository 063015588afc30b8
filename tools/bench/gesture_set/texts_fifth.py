"""The fifth held-out text set of ``gesturecast bench gestures`` (``--stories fifth``): written after the fourth set's
run and before the sixth phrase revision (the presenting grammar), committed on its own before any change to the
rules, the training sentences or the classifier, and run once at the end. Never used to write rules or to train the
classifier.

The conventions are those of :mod:`gesturecast.tools.bench.gesture_set.texts`. Six cued stories in situations the
other sets lack (a flat viewing, a podcast studio, a laboratory induction, a wedding reception, a support hotline, a
club's open day) and 6.4 minutes of narration (106 sentences) in nine voices none of the other sets uses: a museum
audio guide, a property listing, a laboratory protocol, a podcast introduction, a news bulletin, a sermon, a support
call transcript, a football commentary and an obituary, with this / these / here / there / look at / meet / welcome
/ thanks to / take care / see you / come on / cheers / bye / hello in ordinary use.
"""

from __future__ import annotations

CUED_STORIES_FIFTH: dict[str, tuple[str, ...]] = {
    "flat-viewing": (
        "[wave]Morning, you must be the Hendersons.",
        "[guide]This is the living room, with the original fireplace.",
        "The landlord painted every wall last spring.",
        "[guide]And here's the second bedroom, facing the garden.",
        "[bow]Thanks for coming round on such short notice.",
    ),
    "podcast-studio": (
        "[wave]Hey there, and [wave]welcome to episode one hundred.",
        "[raise-both]Woohoo, we actually made it!",
        "My guest today has written six novels about the sea.",
        "[bow]Thank you so much for joining me, Priya.",
        "[bye]Take care, everybody, and [bye]see you next week.",
    ),
    "lab-induction": (
        "[wave]Hi all, [wave]welcome to the chemistry lab.",
        "[guide]Over here is the fume cupboard for anything volatile.",
        "Goggles stay on from the moment you pass the yellow line.",
        "[call]Come over and have a look at the scales.",
        "[bow]Thanks, that was a quick first tour.",
    ),
    "wedding-reception": (
        "[wave]Good evening, friends and family.",
        "[raise-both]Hip hip hooray for the happy couple!",
        "[bow]A big thank you to the caterers, the food was superb.",
        "[guide]Allow me to introduce the best man, Daniel.",
        "[call]Everyone come up to the dance floor!",
        "[bye]Goodnight, and [bye]safe travels home.",
    ),
    "support-hotline": (
        "[wave]Hello, you're through to technical support.",
        "The router restarts itself when the update finishes.",
        "[raise-both]Brilliant, the light is green again!",
        "[bow]Thanks ever so much for your help.",
        "[bye]Bye now.",
    ),
    "open-day": (
        "[wave]Welcome, welcome, come in out of the rain.",
        "[guide]Meet Coach Ellis, who runs the under twelves.",
        "[guide]Have a look at the new pitch, it was laid in August.",
        "[call]Come join us for a kick about after lunch.",
        "[raise-both]Congratulations to our girls on winning the cup!",
        "[bye]Farewell, and [bow]thanks for visiting.",
    ),
}

NARRATION_FIFTH: tuple[str, ...] = (
    # a museum audio guide
    "This is one of only four portraits the painter finished in his last year.",
    "These are the colours he could afford after the bank failed.",
    "There is a hidden signature in the lower corner, under the varnish.",
    "Here the restorers found an earlier sketch of a different face.",
    "Look at the hands before you move on, they were painted by an assistant.",
    "Thanks to an x-ray taken in the sixties, we know the sitter was his sister.",
    "Over there, in the next room, hang the landscapes of his early years.",
    "Welcome guests of the duke often stayed in the house shown in the background.",
    "This is a question the catalogue still leaves open.",
    "The sitter meets our gaze without a trace of a smile.",
    "Take care to keep behind the rope, the frame is very fragile.",
    "Hello and goodbye are written in Latin on the open book beside her.",
    # a property listing
    "This is a rare chance to buy on one of the quietest streets in town.",
    "These are the best kept gardens on the whole estate.",
    "There is a utility room behind the kitchen and a cellar below.",
    "Here the ceilings are almost three metres high.",
    "Thanks to new double glazing, heating bills are remarkably low.",
    "The owners will take care of the carpets before completion.",
    "Over there, across the green, is a primary school rated outstanding.",
    "Come spring, the cherry tree fills the front window with blossom.",
    "This is the second time the house has come on the market in fifty years.",
    "Look at the floor plan and you will see how much light the rooms get.",
    "Viewings are welcome on weekdays after five.",
    "See you at the open house is printed on every flyer in the agent's window.",
    # a laboratory protocol
    "This is the step where most students lose their sample.",
    "These are the only reagents that can be kept at room temperature.",
    "There must be no bubbles in the tube before it goes into the centrifuge.",
    "Here the solution should turn a pale yellow.",
    "Take care that the lid is closed before pressing start.",
    "Look at the meniscus at eye level when you read the volume.",
    "Thanks to the buffer, the enzyme stays active for about an hour.",
    "The two layers meet at a sharp line once the mixture has settled.",
    "This is not the moment to change gloves.",
    "Over there, beside the sink, the waste bottles are labelled by colour.",
    "Come back after ten minutes and the crystals will have formed.",
    "These are the results you should expect if everything has gone well.",
    # a podcast introduction
    "This is a show about the small decisions that change a life.",
    "These are stories we collected over two years of travelling.",
    "There are eight episodes, and each one stands on its own.",
    "Here we ask what people would do differently if they could.",
    "Thanks to our listeners, the first season reached forty countries.",
    "This week's guest grew up on a farm and now flies cargo planes.",
    "She says hello was the hardest word to learn in Japanese.",
    "Look at any airport at night and you will find people like her.",
    "Welcome as the money was, she says the job nearly broke her.",
    "Meet the people behind the headlines is the idea of the whole series.",
    "See you on the other side, her instructor told her before her first solo flight.",
    "Cheers and tears, she says, came in roughly equal measure.",
    # a news bulletin
    "This is the third storm to hit the coast since October.",
    "These are the highest river levels recorded in forty years.",
    "There are reports of flooding in at least six villages.",
    "Here in the capital, schools will open as normal tomorrow.",
    "Thanks to early warnings, nobody was hurt when the bridge collapsed.",
    "The prime minister will meet flood victims on Thursday.",
    "Over there, in the north, the snow has closed two mountain passes.",
    "Rescue teams say residents should take care near fallen power lines.",
    "The street lights came on at noon as the clouds darkened the sky.",
    "This is a developing story and we will bring you updates through the day.",
    "Farmers say the rain was welcome after a dry summer, but not this much.",
    "Goodbye to the old tax rules, the finance minister told parliament on Monday.",
    # a sermon
    "This is the hardest passage in the whole book.",
    "These are words that have comforted people for centuries.",
    "There was once a shepherd who lost one sheep out of a hundred.",
    "Here the story takes a turn nobody expected.",
    "Look at how the father runs to meet his son on the road.",
    "Thanks to his mercy, the younger son is given a second chance.",
    "Welcome home, the father says, and orders a feast.",
    "The elder brother will not come in, and stays outside in the dark.",
    "This is what forgiveness costs.",
    "Take care of one another is the only rule the old preacher ever wrote down.",
    "Over there, in the fields, the elder son heard the music.",
    "These are the questions I would like us to carry into the week.",
    # a support call transcript
    "This is the part of the call where the customer finally reads the error code.",
    "There is a known fault with that model when the battery is low.",
    "Here the agent asks for the serial number on the back of the box.",
    "Thanks to the remote session, the problem was found within minutes.",
    "The customer says hi to her neighbour, who has come in to help.",
    "Look at the light on the front, the agent says, is it blinking or steady?",
    "Take care when you unplug it, the cable is easily damaged.",
    "These are the steps that fixed the problem for most people.",
    "Come on, the customer mutters at the screen while it restarts.",
    "Over there, in another office, a second agent is checking the account.",
    "Bye for now, the agent says, and the call ends after nineteen minutes.",
    "This is a typical call, and most of them end the same way.",
    # a football commentary
    "This is the first time the two sides have met in a final.",
    "These are the moments that players dream about as children.",
    "There is the cross, and the keeper gathers it cleanly.",
    "Here comes the substitute, fresh legs for the last ten minutes.",
    "Thanks to a deflection, the ball loops over the wall.",
    "Over there, the away fans are already singing.",
    "Look at the space down the left, nobody is tracking the full back.",
    "Come on is all you can hear from the home end.",
    "The cheers die down as the referee checks the replay.",
    "This is the best goal of the season, and it is not even close.",
    "The two captains meet in the centre circle for the coin toss.",
    "See you next year, the chants say, as the losing side walks off.",
    # an obituary
    "This is a town that will miss her for a long time.",
    "These are the streets she walked every morning for sixty years.",
    "There were three hundred people at the funeral on Saturday.",
    "Here she ran the post office until she was eighty.",
    "Thanks to her, a whole generation of children learned to swim.",
    "She would say hello to every stranger who came into the shop.",
    "Welcome or not, her advice arrived with every parcel.",
    "Her daughter said goodbye on a bright morning in June.",
    "Take care, she would call after anyone who left in the rain, and they always did.",
    "This is the bench by the river where she liked to sit.",
)
