"""`gesturecast gestures build | list | train-acts`: the gesture lexicon and the speech-act classifier
(docs/gestures.md).

``build`` reads the labelled Bandai Namco takes of the training data folder (both archives, unpacked once into
``.cache/raw`` as ``gesturecast data build`` does), retargets them like the dataset cache, trims each take to its
gesture, marks the stroke and writes ``lexicon.json`` + ``clips.npz`` (default ``models/weights/gestures``, the
lexicon that ships). ``list`` prints a lexicon: the shipped one, a built one, or a user folder of clips with its
``gestures.json``. ``train-acts`` fits the classifier that decides cues from the phrase on the sentences written for
it and writes its weights. All need numpy only (no torch).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

DEFAULT_OUT = Path("models/weights/gestures")
DEFAULT_RAW = Path(".cache/raw")
DEFAULT_ACTS = Path("models/weights/gestures/speech_acts.npz")
PHRASES_SHOWN = 5  # of a speech act's phrases, in `gestures list`


def register(subparsers: argparse._SubParsersAction) -> None:
    gestures = subparsers.add_parser("gestures", help="the gesture lexicon: build it from the Bandai takes, list it")
    commands = gestures.add_subparsers(dest="gestures_command", required=True)
    build = commands.add_parser("build", help="trim the labelled Bandai takes to their gestures, write the lexicon")
    build.add_argument("--shared", type=Path, default=None, metavar="DATA",
                       help="the training data folder, holding bandai/ (default: `gesturecast data build`'s)")
    build.add_argument("--out", type=Path, default=DEFAULT_OUT, help="lexicon folder (default %(default)s)")
    build.add_argument("--raw-cache", type=Path, default=DEFAULT_RAW,
                       help="where the archives are unpacked (default %(default)s)")
    build.add_argument("--per-style", type=int, default=None, metavar="N",
                       help="read at most N takes per gesture and style (default: all; a quick build: 3)")
    build.add_argument("--styles", type=int, default=None, metavar="N",
                       help="keep at most N styles per gesture (default 5)")
    build.add_argument("--takes", type=int, default=None, metavar="N",
                       help="keep at most N takes per gesture and style (default 3)")
    build.set_defaults(func=run_build)
    listing = commands.add_parser("list", help="print a lexicon: the gesture each speech act plays, then each "
                                  "gesture's parts, duration, stroke, styles and what it shows (or its triggers)")
    listing.add_argument("--lexicon", type=Path, default=None, metavar="DIR",
                         help="a built lexicon or a folder of your clips with gestures.json (default: the shipped one)")
    listing.add_argument("--json", action="store_true", help="one JSON document instead of the table")
    listing.set_defaults(func=run_list)
    acts = commands.add_parser("train-acts", help="train the speech-act classifier that decides cues from phrases "
                               "(numpy, about a minute)")
    acts.add_argument("--out", type=Path, default=DEFAULT_ACTS, help="weights file (default %(default)s)")
    acts.set_defaults(func=run_train_acts)


def _positive(value: int | None, flag: str) -> None:
    from gesturecast.errors import UserError

    if value is not None and value < 1:
        raise UserError(f"{flag} must be at least 1, got {value}")


def run_build(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from gesturecast.errors import UserError
    from gesturecast.models.dataset.cache import read_take
    from gesturecast.models.dataset.sources import TakeSource, bandai_takes, unpack_archive
    from gesturecast.tools.data_cli import BANDAI_ARCHIVES, DEFAULT_SHARED
    from gesturecast.tools.gestures import build as lexicon_module

    _positive(args.per_style, "--per-style")
    _positive(args.styles, "--styles")
    _positive(args.takes, "--takes")
    shared = DEFAULT_SHARED if args.shared is None else args.shared
    bandai = shared / "bandai"
    if not bandai.is_dir():
        raise UserError(f"no bandai/ folder in {shared} (pass --shared DATA, the training data folder)")
    started = time.perf_counter()
    takes: list[TakeSource] = []
    for archive in BANDAI_ARCHIVES:
        takes += bandai_takes(unpack_archive(bandai / archive, args.raw_cache / "bandai"))
    sources = {Path(take.motion_path): take for take in takes}
    candidates = lexicon_module.select_candidates(lexicon_module.bandai_gesture_takes(takes), args.per_style)
    if not candidates:
        raise UserError(f"no gesture takes found in {bandai}")

    def read(path: Path):
        return read_take(sources[path])[0]

    lexicon = lexicon_module.build_lexicon(
        candidates, read, progress=lambda items: tqdm(items, desc="gesture takes", unit="take"),
        max_variants=args.styles or lexicon_module.MAX_VARIANTS, max_takes=args.takes or lexicon_module.MAX_TAKES)
    missing = [name for name in lexicon_module.GESTURE_NAMES if name not in lexicon]
    if missing:
        raise UserError(f"no usable take (starting and ending with the arms down) for: {', '.join(missing)}")
    paths = lexicon_module.save_lexicon(lexicon, args.out)
    print(format_table(lexicon))
    print(json.dumps({"gestures": len(lexicon), "clips": sum(len(e.variants) for e in lexicon),
                      "takes_read": len(candidates), "skipped_styles": lexicon.metadata.get("skipped", []),
                      "bytes": {p.name: p.stat().st_size for p in paths},
                      "total_bytes": sum(p.stat().st_size for p in paths),
                      "build_seconds": round(time.perf_counter() - started, 1), "out": str(args.out)}))
    return 0


def format_table(lexicon, last_column: str = "triggers") -> str:
    """A plain-text table: name, parts, duration, stroke, styles (the default style's clip's times), then the trigger
    words (a user's folder) or what a person sees (``last_column="shows"``, a built lexicon cued by speech acts)."""
    header = ("name", "parts", "duration", "stroke", "styles", last_column)
    rows = [(e.name, "+".join(e.parts), f"{e.duration:.2f} s", f"{e.stroke_time:.2f} s", ", ".join(e.styles),
             (", ".join(e.triggers) if last_column == "triggers" else e.description) or "-") for e in lexicon]
    return aligned([header, *rows])


def aligned(rows: list[tuple[str, ...]]) -> str:
    """Rows of cells as columns padded to their widest cell (the last column as it is)."""
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]) - 1)]
    lines = ["  ".join(cell.ljust(width) for cell, width in zip(row[:-1], widths, strict=True)) + "  " + row[-1]
             for row in rows]
    return "\n".join(line.rstrip() for line in lines)


def speech_acts(lexicon) -> dict[str, dict]:
    """What a built lexicon plays for each speech act: {act: {"plays": gesture, "phrases": [...]}}, the acts it has a
    gesture for, in the phrasebook's order."""
    from gesturecast.realtime.gestures.phrasebook import PHRASEBOOK
    from gesturecast.realtime.gestures.phrases import PhraseCues

    cues = PhraseCues(lexicon.entries)
    return {act: {"plays": cues.gesture_of(act), "phrases": list(phrases)} for act, phrases in PHRASEBOOK.items()
            if cues.gesture_of(act) is not None}


def speech_act_table(acts: dict[str, dict], lexicon) -> str:
    """Speech act, the gesture it plays and some of its phrases; then the gestures no speech act plays."""
    rows = [("speech act", "plays", "when someone says")]
    rows += [(act, act_cue["plays"], ", ".join(act_cue["phrases"][:PHRASES_SHOWN]) + ", …")
             for act, act_cue in acts.items()]
    played = {act_cue["plays"] for act_cue in acts.values()}
    on_request = [entry.name for entry in lexicon if entry.name not in played]
    table = aligned(rows)
    if not on_request:
        return table
    return table + ("\non request only (a gesture control: the viewer's buttons, OSC, Stream.gesture): "
                    + ", ".join(on_request))


def run_list(args: argparse.Namespace) -> int:
    from gesturecast.realtime.gestures.lexicon import LEXICON_FILE, default_lexicon_dir, load_lexicon

    lexicon = load_lexicon(args.lexicon)
    built = (Path(args.lexicon or default_lexicon_dir()) / LEXICON_FILE).is_file()  # cued by speech acts
    acts = speech_acts(lexicon) if built else {}
    if args.json:
        print(json.dumps({"source": lexicon.source, "license": lexicon.license, "speech_acts": acts,
                          "gestures": lexicon.summary()}, indent=1))
        return 0
    if built:
        print(speech_act_table(acts, lexicon) + "\n")
    print(format_table(lexicon, "shows" if built else "triggers"))
    if lexicon.license:
        print(lexicon.license)
    return 0


def run_train_acts(args: argparse.Namespace) -> int:
    from gesturecast.tools.gestures.speech_act_data import training_sentences
    from gesturecast.tools.gestures.speech_act_training import train

    started = time.perf_counter()
    model, info = train(training_sentences())
    args.out.parent.mkdir(parents=True, exist_ok=True)
    model.save(args.out)
    print(json.dumps({**info, "out": str(args.out), "seconds": round(time.perf_counter() - started, 1)}))
    return 0
