"""The wheel: built offline from a copy of the source tree, it holds what the runtime needs (the default model, the
gesture lexicon, the viewer page and its libraries, the avatar, the sample, the licence notes) and nothing that is
not the product; and a non-editable install of it finds all of that inside itself, from any working folder."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import zipfile
from importlib import metadata
from pathlib import Path

import pytest

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    tomllib = pytest.importorskip("tomli")

REPO = Path(__file__).resolve().parents[1]
MIN_SETUPTOOLS = (77,)  # SPDX `license` expressions (pyproject.toml's build-system.requires)
# what a clean clone would not have: version control, environments, build and run outputs, caches
NOT_COPIED = shutil.ignore_patterns(".git", ".venv", "build", "dist", "*.egg-info", "out", ".cache", ".pytest_cache",
                                    ".ruff_cache", "node_modules")
# files a working tree may hold inside the package folders, which must never ship (planted in the copy)
PLANTED = ("bridges/__pycache__/vmc.cpython-311.pyc", "models/weights/default/__pycache__/junk.cpython-311.pyc",
           "models/weights/.cache/junk.npz", "tools/viewer_bundle/node_modules/three/package.json",
           "gesturecast/samples/.DS_Store")
PIP_TIMEOUT_S = 120


def pip(*args: str, cwd: Path) -> str:
    """Run this environment's pip offline; its combined output (the test fails with it when pip fails)."""
    env = {**os.environ, "PIP_DISABLE_PIP_VERSION_CHECK": "1", "PIP_NO_INPUT": "1"}
    env.pop("PYTHONWARNINGS", None)  # every warning of the build must show
    result = subprocess.run([sys.executable, "-m", "pip", *args], cwd=cwd, env=env, capture_output=True, text=True,
                            timeout=PIP_TIMEOUT_S)
    output = result.stdout + result.stderr
    assert result.returncode == 0, output
    return output


@pytest.fixture(scope="module")
def source(tmp_path_factory) -> Path:
    """A copy of the working tree as a clean clone has it, plus stray files that must not reach the wheel."""
    copy = tmp_path_factory.mktemp("source") / "gesturecast"
    shutil.copytree(REPO, copy, ignore=NOT_COPIED)
    for name in PLANTED:
        (copy / name).parent.mkdir(parents=True, exist_ok=True)
        (copy / name).write_bytes(b"not part of the product")
    return copy


@pytest.fixture(scope="module")
def built(source, tmp_path_factory) -> tuple[Path, str]:
    """(the wheel, pip's output) from ``pip wheel --no-deps --no-build-isolation --no-index`` on the copy."""
    version = tuple(int(part) for part in metadata.version("setuptools").split(".")[:1])
    assert version >= MIN_SETUPTOOLS, "setuptools >= 77 is needed to build offline: `make test` installs it"
    out = tmp_path_factory.mktemp("wheel")
    output = pip("wheel", "--no-deps", "--no-build-isolation", "--no-index", "-w", str(out), str(source), cwd=out)
    (wheel,) = out.glob("gesturecast-*.whl")
    return wheel, output


@pytest.fixture(scope="module")
def names(built) -> set[str]:
    with zipfile.ZipFile(built[0]) as archive:
        return set(archive.namelist())


@pytest.fixture(scope="module")
def dist_info(names) -> str:
    (folder,) = {name.split("/")[0] for name in names if name.split("/")[0].endswith(".dist-info")}
    return folder


def files_under(folder: Path) -> set[str]:
    """The files below ``folder`` (relative, POSIX), leaving out bytecode folders and dotfiles."""
    relative = (p.relative_to(folder) for p in folder.rglob("*") if p.is_file())
    return {p.as_posix() for p in relative if not any(part.startswith((".", "__pycache__")) for part in p.parts)}


def test_the_build_prints_no_warning(built):
    warnings = [line for line in built[1].splitlines() if "warn" in line.lower()]
    assert warnings == []


def test_the_wheel_holds_the_model_viewer_avatar_sample_and_licence_notes(names, dist_info, source):
    default = files_under(source / "models" / "weights" / "default")
    assert "model.json" in default and {name for name in default if name.endswith(".onnx")}
    assert {f"gesturecast/models/weights/default/{name}" for name in default} <= names
    assert {f"gesturecast/models/weights/eval/{name}" for name in files_under(source / "models/weights/eval")} <= names
    gestures = files_under(source / "models" / "weights" / "gestures")  # the gesture lexicon (docs/gestures.md)
    assert gestures == {"lexicon.json", "clips.npz", "speech_acts.npz"}  # the lexicon and the speech-act classifier
    assert {f"gesturecast/models/weights/gestures/{name}" for name in gestures} <= names
    assert "gesturecast/models/weights/speech_embedding/embedding_frames.onnx" in names  # the default model hears it
    viewer = {name for name in files_under(source / "bridges" / "viewer") if "/" not in name}  # the page's own files
    assert {"index.html", "viewer.js"} <= viewer
    assert {f"gesturecast/bridges/viewer/{name}" for name in viewer} <= names
    vendor = {"three-vrm.bundle.js", "three.LICENSE", "three-vrm.LICENSE", "three-vrm-animation.LICENSE"}
    assert {f"gesturecast/bridges/viewer/vendor/{name}" for name in vendor} <= names
    avatar = "gesturecast/bridges/viewer/avatar/cryptovoxels"
    assert {f"{avatar}.vrm", f"{avatar}.LICENSE",
            "gesturecast/samples/sample_speech.wav", "gesturecast/samples/README.md",
            "gesturecast/models/weights/LICENSE.md"} <= names
    licences = {"LICENSE", "models/weights/LICENSE.md", "bridges/viewer/avatar/cryptovoxels.LICENSE",
                "bridges/viewer/vendor/three.LICENSE", "gesturecast/samples/README.md"}
    assert {f"{dist_info}/licenses/{name}" for name in licences} <= names


def test_the_wheel_holds_every_module_of_the_source_folders(names, source):
    """Every .py under the folders pyproject.toml's package-dir maps (a new subpackage cannot be forgotten)."""
    package_dir = tomllib.loads((source / "pyproject.toml").read_text())["tool"]["setuptools"]["package-dir"]
    expected = {f"{package.replace('.', '/')}/{name}" for package, folder in package_dir.items()
                for name in files_under(source / folder) if name.endswith(".py")}
    assert expected and expected <= names, sorted(expected - names)[:10]


def test_the_wheel_holds_nothing_else(names, dist_info):
    """Only the gesturecast package and its metadata: no tests, caches, bytecode, npm sources or dotfiles."""
    assert all(name.startswith(("gesturecast/", f"{dist_info}/")) for name in names), sorted(names)[:5]
    unwanted = {"tests", "__pycache__", ".cache", "node_modules", "viewer_bundle", "docs", "examples"}
    leaked = [name for name in names if unwanted & set(name.split("/")) or name.endswith(".pyc") or "/." in name]
    assert leaked == []


# run by the installed copy, from a folder with nothing of the project in it: where its packaged files are
INSTALLED_CHECK = """
import json
from importlib import resources
import gesturecast
from gesturecast.bridges.avatar_file import resolve_avatar
from gesturecast.cli import build_parser
from gesturecast.models.evaluation.fgd_encoder import DEFAULT_FGD_ENCODER
from gesturecast.models.runtime.bundle import ONNX_FILES, ModelBundle
from gesturecast.realtime.gestures.lexicon import default_lexicon_dir, load_lexicon
from gesturecast.tools import demo_cli

model = build_parser().parse_args(["live", "--ws", "0"]).model  # the CLI's default --model
bundle = ModelBundle.load(model)
viewer = resources.files("gesturecast.bridges") / "viewer"
avatar = resolve_avatar(None, {})
print(json.dumps({
    "package": gesturecast.__file__,
    "model": [str(model / "model.json"), *(str(bundle.path(name)) for name in ONNX_FILES)],
    "viewer": [str(viewer / "index.html"), str(viewer / "vendor" / "three-vrm.bundle.js")],
    "avatar": [str(avatar), str(avatar.with_suffix(".LICENSE"))],
    "sample": [str(demo_cli.PACKAGED_SAMPLE)],
    "eval": [str(DEFAULT_FGD_ENCODER)],
    "gestures": [str(default_lexicon_dir() / name) for name in ("lexicon.json", "clips.npz")
                 if load_lexicon()["wave"].variant().num_frames],
}))
"""


def test_an_installed_wheel_finds_its_model_viewer_avatar_and_sample_inside_itself(built, tmp_path):
    target = tmp_path / "site"
    pip("install", "--no-deps", "--no-index", "--target", str(target), str(built[0]), cwd=tmp_path)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {**os.environ, "PYTHONPATH": str(target)}  # the installed copy comes before the editable one
    env.pop("GESTURECAST_AVATAR", None)
    result = subprocess.run([sys.executable, "-c", INSTALLED_CHECK], cwd=elsewhere, env=env, capture_output=True,
                            text=True, timeout=PIP_TIMEOUT_S)
    assert result.returncode == 0, result.stderr
    found = json.loads(result.stdout.splitlines()[-1])
    root = target.resolve()
    assert Path(found.pop("package")).resolve().is_relative_to(root / "gesturecast")
    for what, paths in found.items():
        for path in map(Path, paths):
            assert path.resolve().is_relative_to(root) and path.is_file(), f"{what}: {path}"
    assert Path(found["avatar"][0]).read_bytes()[:4] == b"glTF"


def test_an_installed_wheel_generates_from_any_folder_with_the_one_liner(built, tmp_path):
    """What the README promises a new user: ``generate('talk.wav', style='happy').save('talk.bvh')``."""
    import soundfile

    from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio
    from gesturecast.models.motion.bvh import read_bvh

    target = tmp_path / "site"
    pip("install", "--no-deps", "--no-index", "--target", str(target), str(built[0]), cwd=tmp_path)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    soundfile.write(elsewhere / "talk.wav", load_audio(PACKAGED_SAMPLE)[: 2 * SAMPLE_RATE], SAMPLE_RATE)
    code = ("import gesturecast; m = gesturecast.generate('talk.wav', style='happy'); m.save('talk.bvh'); "
            "print(gesturecast.__file__)")
    result = subprocess.run([sys.executable, "-c", code], cwd=elsewhere, env={**os.environ, "PYTHONPATH": str(target)},
                            capture_output=True, text=True, timeout=PIP_TIMEOUT_S)
    assert result.returncode == 0, result.stderr
    assert Path(result.stdout.strip()).resolve().is_relative_to(target.resolve())
    assert read_bvh(elsewhere / "talk.bvh").num_frames == 2 * 30
