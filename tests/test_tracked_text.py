"""The repository's own text stays clean: no work-organisation notes, no internal tool names, no references to
files outside the repository, no broken links in the Markdown documentation, and a README for users.

Files are those git knows (tracked, or new and not ignored); binary files and vendored bundles are skipped.
The patterns below are assembled from pieces so that this file does not match them itself.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
THIS_FILE = Path(__file__).resolve().relative_to(ROOT).as_posix()
VENDORED_PREFIXES = ("bridges/viewer/vendor/",)
BINARY_PROBE_BYTES = 8192
README_MAX_BYTES = 15_000
SESSION = "sess" + "ion"
ISSUE = "iss" + "ue"

# name -> pattern (case-insensitive); a match anywhere in a text file fails the test
FORBIDDEN: dict[str, re.Pattern[str]] = {
    "work-organisation note": re.compile(rf"\b{SESSION}s?[ -]#?\d|\bthis {SESSION}\b", re.IGNORECASE),
    "ticket reference": re.compile(rf"\b{ISSUE}s? #?\d|\bthe {ISSUE}'s\b", re.IGNORECASE),
    "internal tool name": re.compile(
        "|".join(re.escape(name) for name in ("farm" + "-bench", "farm" + "-studio", "duplicates" + " --change")),
        re.IGNORECASE),
}
OUTSIDE_REFERENCE = re.compile(
    "|".join(re.escape(name) for name in (".." + "/shared", "DESIGN" + ".md", "/work" + "/shared")))

# Files allowed to name a path outside the repository, and why. Remove an entry once its reason is gone.
OUTSIDE_REFERENCE_ALLOWED = {
    "tools/data_cli.py": "the data build's --shared default still points beside the checkout",
    "tools/bench/vad.py": "bench vad's default speech files still point to the shared data folder",
    "tools/bench/speech/lipsync.py": "bench lipsync's default data folder still points to the shared data folder",
    "tests/bridges/test_avatar_file.py": "checks that the avatar is not looked up beside the checkout",
    "tests/bridges/test_viewer_avatar.py": "checks that the avatar is not looked up beside the checkout",
}

LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
FENCED_BLOCK = re.compile(r"^(```|~~~).*?^\1[^\n]*$", re.MULTILINE | re.DOTALL)
INLINE_CODE = re.compile(r"`[^`\n]*`")
HEADING = re.compile(r"^#{1,6}\s+(.+?)\s*#*\s*$", re.MULTILINE)
EXTERNAL = re.compile(r"^[a-z][a-z0-9+.-]*:", re.IGNORECASE)  # http:, https:, mailto:, ...

AUDIENCE_SECTIONS = {
    "VTubers": r"vtuber",
    "Unity / Unreal": r"unity.*unreal|unreal.*unity",
    "browser viewer": r"browser",
    "voice agents": r"voice agent",
    "Python / robots": r"python|robot",
    "batch files": r"batch",
}


def known_files() -> list[str]:
    """Paths (relative, POSIX) of the files git tracks or would add, that exist in the working tree."""
    try:
        listing = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=ROOT,
                                 capture_output=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout")
    names = sorted({name for name in listing.decode("utf-8").split("\0") if name})
    return [name for name in names if (ROOT / name).is_file()]


def text_of(name: str) -> str | None:
    """The file's text, or None for binary files (a NUL byte, or not UTF-8)."""
    data = (ROOT / name).read_bytes()
    if b"\0" in data[:BINARY_PROBE_BYTES]:
        return None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return None


@pytest.fixture(scope="module")
def texts() -> dict[str, str]:
    out = {}
    for name in known_files():
        if name == THIS_FILE or name.startswith(VENDORED_PREFIXES):
            continue
        text = text_of(name)
        if text is not None:
            out[name] = text
    return out


def line_hits(text: str, pattern: re.Pattern[str]) -> list[tuple[int, str]]:
    return [(number, match.group(0)) for number, line in enumerate(text.splitlines(), 1)
            for match in pattern.finditer(line)]


def test_there_is_text_to_check(texts):
    assert "README.md" in texts
    assert any(name.endswith(".py") for name in texts)


@pytest.mark.parametrize("kind", sorted(FORBIDDEN))
def test_no_forbidden_words(texts, kind):
    pattern = FORBIDDEN[kind]
    hits = [f"{name}:{number}: {found!r}" for name, text in texts.items() for number, found in line_hits(text, pattern)]
    assert not hits, f"{kind} in tracked text (rephrase with dates and versions):\n" + "\n".join(hits)


def test_no_references_outside_the_repository(texts):
    hits = [f"{name}:{number}: {found!r}" for name, text in texts.items() if name not in OUTSIDE_REFERENCE_ALLOWED
            for number, found in line_hits(text, OUTSIDE_REFERENCE)]
    assert not hits, "paths outside the repository:\n" + "\n".join(hits)


def markdown_files(texts: dict[str, str]) -> list[str]:
    return [name for name in texts
            if name in ("README.md", "CHANGELOG.md") or (name.startswith("docs/") and name.endswith(".md"))]


def without_code(text: str) -> str:
    """Markdown without fenced blocks and inline code (their brackets are not links), line numbers kept."""
    text = FENCED_BLOCK.sub(lambda block: "\n" * block.group(0).count("\n"), text)
    return INLINE_CODE.sub("", text)


def heading_anchors(text: str) -> set[str]:
    """GitHub's anchors for the headings of a Markdown text (a repeated heading gets -1, -2, ...)."""
    anchors: set[str] = set()
    seen: dict[str, int] = {}
    for heading in HEADING.findall(FENCED_BLOCK.sub("", text)):
        heading = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link in a heading keeps its text
        slug = re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")
        count = seen.get(slug, 0)
        seen[slug] = count + 1
        anchors.add(slug if count == 0 else f"{slug}-{count}")
    return anchors


def broken_link(source: str, target: str, texts: dict[str, str]) -> str | None:
    """Why a relative link of ``source`` is broken, or None."""
    path_part, _, anchor = target.partition("#")
    resolved = (ROOT / source).parent / path_part if path_part else ROOT / source
    try:
        relative = resolved.resolve().relative_to(ROOT).as_posix()
    except ValueError:
        return "points outside the repository"
    if not resolved.exists():
        return "no such file or folder"
    if anchor and relative.endswith(".md") and resolved.is_file():
        text = texts.get(relative) or resolved.read_text(encoding="utf-8")
        if anchor.lower() not in heading_anchors(text):
            return f"no heading for #{anchor} in {relative}"
    return None


def test_markdown_links_resolve(texts):
    problems = []
    for name in markdown_files(texts):
        for number, line in enumerate(without_code(texts[name]).splitlines(), 1):
            for target in LINK.findall(line):
                if EXTERNAL.match(target):
                    continue
                reason = broken_link(name, target, texts)
                if reason:
                    problems.append(f"{name}:{number}: ({target}) {reason}")
    assert not problems, "broken links:\n" + "\n".join(problems)


def test_readme_is_short():
    size = (ROOT / "README.md").stat().st_size
    assert size <= README_MAX_BYTES, f"README.md is {size} bytes; the limit is {README_MAX_BYTES}"


def test_readme_has_a_section_per_audience():
    headings = [heading.lower() for heading in re.findall(r"^##\s+(.+)$", (ROOT / "README.md").read_text("utf-8"),
                                                           re.MULTILINE)]
    missing = [audience for audience, pattern in AUDIENCE_SECTIONS.items()
               if not any(re.search(pattern, heading) for heading in headings)]
    assert not missing, f"README.md has no section for: {', '.join(missing)} (headings: {headings})"


def test_link_checker_sees_a_broken_link(texts):
    assert broken_link("README.md", "docs/no-such-page.md", texts) == "no such file or folder"
    assert broken_link("README.md", "docs/results.md#no-such-heading", texts).startswith("no heading")
    assert broken_link("docs/results.md", "../../outside.md", texts) == "points outside the repository"
    assert heading_anchors("## Access: origin, token, limits\n## A b\n## A b\n") == {
        "access-origin-token-limits", "a-b", "a-b-1"}
    assert line_hits("see " + SESSION + " 7 notes", FORBIDDEN["work-organisation note"])
