import argparse

from gesturecast.realtime.audio import source_flags as audio_cli
from gesturecast.realtime.audio.sources import FastFileSource, PacedFileSource


def parse(argv):
    parser = argparse.ArgumentParser()
    audio_cli.add_source_arguments(parser)
    return parser.parse_args(argv)


def test_input_flag_selects_a_file_source(shared_data):
    wav = str(shared_data / "speech" / "tts_01_en-us.wav")
    assert isinstance(audio_cli.open_source(parse(["--input", wav])), PacedFileSource)
    fast = audio_cli.open_source(parse(["--input", wav, "--pace", "fast", "--block-size", "160"]))
    assert isinstance(fast, FastFileSource) and fast.chunk_samples == 160


def test_devices_command_says_what_to_do_without_a_microphone(capsys):
    code = audio_cli.run_devices(argparse.Namespace())
    out = capsys.readouterr().out
    assert (code == 1 and "--input FILE" in out) or (code == 0 and "Hz" in out)
