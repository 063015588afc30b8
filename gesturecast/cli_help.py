"""What ``gesturecast COMMAND --help`` says besides the flags: one line of purpose and an example or two, in plain
words, for the person at the terminal. Applied to every command's parser by :func:`describe`."""

from __future__ import annotations

import argparse

# command -> (purpose, example command lines)
HELP: dict[str, tuple[str, tuple[str, ...]]] = {
    "render": ("Draw a motion file (BVH, or SMPL-X .npz) as a stick figure, front and side, to a GIF, PNG or MP4.",
               ("gesturecast render talk.bvh -o talk.gif",
                "gesturecast render talk.bvh -o sheet.png --start 10 --seconds 5")),
    "data": ("Prepare the training data: read the motion-capture takes and their audio into one cache that "
             "`gesturecast train` reads.", ("gesturecast data build --shared DATA",)),
    "gestures": ("The gesture lexicon: the gestures (wave, bow, ...) and the words that trigger them; build it "
                 "from the Bandai motion-capture takes, or list it.",
                 ("gesturecast gestures list", "gesturecast gestures build --shared DATA")),
    "devices": ("List the microphones gesturecast can listen to (for `gesturecast live --device`).",
                ("gesturecast devices",)),
    "bench": ("Measure speed and quality; every benchmark prints JSON.",
              ("gesturecast bench latency gesturecast/samples/sample_speech.wav --json",
               "gesturecast bench face --json")),
    "train": ("Train your own gesture model from the training-data cache (needs torch: "
              "pip install torch==2.13.0 && pip install 'gesturecast[train]').",
              ("gesturecast train --preset default --out models/weights/mine",)),
    "export": ("Turn a training checkpoint into a model folder that `live`, `generate` and `serve` load (--model).",
               ("gesturecast export .cache/train/default -o models/weights/mine",)),
    "live": ("Listen to a microphone (or a recording with --input) and send a gesture pose for every frame, in "
             "real time, to your avatar app, game engine, browser or a BVH file.",
             ("gesturecast live --vmc 127.0.0.1:39539 --style happy",
              "gesturecast live --ws 8765 --input talk.wav")),
    "generate": ("Turn a recording into a motion file (BVH, VRM Animation or JSON), as fast as the computer allows; "
                 "with --batch, a whole folder, or a CSV with columns path, style, seed and transcript.",
                 ("gesturecast generate talk.wav -o talk.bvh --style old",
                  "gesturecast generate talk.wav --transcript words.json -o talk.vrma",
                  "gesturecast generate --batch lines.csv -o gestures/")),
    "demo": ("Play the bundled speech sample through the live engine: no microphone, arguments or network "
             "needed; it ends with the sample, or with --loop replays it until Ctrl-C.",
             ("gesturecast demo", "gesturecast demo --loop --ws 8800")),
    "serve": ("Drive many avatars from one server: clients send audio over a WebSocket and get poses back.",
              ("gesturecast serve --port 8766", "gesturecast serve --workers 4")),
    "eval": ("Score generated motion against real motion capture (speech following, realism, styles); writes JSON.",
             ("gesturecast eval --json scores.json",)),
    "style-fit": ("Fit the stylizer's styles and the style judge from the Bandai styled motion-capture takes "
                  "(numpy only, about half a minute).",
                  ("gesturecast style-fit --takes DATA/bandai/dataset-1.tar.xz",)),
    "eval-train": ("Train the networks `gesturecast eval` scores with (needs torch, as `train` does).",
                   ("gesturecast eval-train",)),
}


def describe(name: str, parser: argparse.ArgumentParser) -> None:
    """Give one command's parser its purpose line and examples, ``-v`` after the command, and, for a command made
    of sub-commands (``data``, ``gestures``, ``bench``), its usage when it is given alone."""
    purpose, examples = HELP[name]
    parser.description = purpose
    parser.epilog = "examples:\n" + "\n".join(f"  {line}" for line in examples)
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument("-v", "--verbose", action="store_true", default=argparse.SUPPRESS, help="debug logging")
    group = next((action for action in parser._actions if isinstance(action, argparse._SubParsersAction)), None)
    if group is not None:
        group.required = False
        group.metavar = "{" + ",".join(group.choices) + "}"
        parser.set_defaults(func=lambda _args: show_usage(parser))


def show_usage(parser: argparse.ArgumentParser) -> int:
    """A group command given alone: its help (the sub-commands, with a line each), exit status 2."""
    parser.print_help()
    return 2
