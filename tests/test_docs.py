"""The documentation stays true: pictures exist, command lines run, and the keyboard
reference lists the keys the code binds (and no others)."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
DOCS = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
KEYBOARD = REPO / "docs" / "keyboard.md"
UI = REPO / "qtanimator" / "ui"


def _rel(path: Path) -> str:
    return str(path.relative_to(REPO))


# ------------------------------------------------------------------ links and images
_LINK = re.compile(r"(!?)\[[^\]]*\]\(([^)\s]+)\)")


def _links(md: Path) -> list[tuple[bool, str]]:
    text = re.sub(r"```.*?```", "", md.read_text(encoding="utf-8"), flags=re.S)
    return [(bang == "!", target) for bang, target in _LINK.findall(text)]


@pytest.mark.parametrize("md", DOCS, ids=_rel)
def test_linked_images_and_files_exist(md: Path) -> None:
    for is_image, target in _links(md):
        if re.match(r"[a-z]+:", target) or target.startswith("#"):
            continue  # web links and anchors within the page
        path = (md.parent / target.split("#")[0]).resolve()
        assert path.exists(), f"{_rel(md)} links to {target}, which does not exist"
        if is_image:
            assert path.suffix.lower() in (".png", ".jpg", ".gif", ".svg"), target
            assert path.stat().st_size > 1000, f"{target} looks empty"


def test_screenshots_are_linked_and_reasonably_small() -> None:
    from PIL import Image

    linked = {(md.parent / t).resolve() for md in DOCS for is_image, t in _links(md) if is_image}
    for png in sorted((REPO / "docs" / "images").glob("*.png")):
        assert png.resolve() in linked, f"{_rel(png)} is not used by any page"
        with Image.open(png) as im:
            assert im.width <= 1400, f"{_rel(png)} is {im.width} px wide"
        assert png.stat().st_size < 400_000, f"{_rel(png)} is larger than 400 kB"


def test_anchor_links_point_at_headings() -> None:
    def slug(heading: str) -> str:
        s = re.sub(r"[^\w\s-]", "", heading.strip().lower())
        return re.sub(r"\s", "-", s)

    for md in DOCS:
        for _img, target in _links(md):
            if "#" not in target or re.match(r"[a-z]+:", target):
                continue
            file, anchor = target.split("#", 1)
            page = (md.parent / file).resolve() if file else md
            headings = {slug(h) for h in re.findall(r"^#+ (.+)$", page.read_text(encoding="utf-8"), re.M)}
            assert anchor in headings, f"{_rel(md)}: no heading for #{anchor} in {page.name}"


# ------------------------------------------------------------------ command lines
def _command_lines() -> list[tuple[str, list[str]]]:
    """Every ``qtanimator …`` line inside a fenced block of the README and docs."""
    found = []
    for md in DOCS:
        for block in re.findall(r"```[^\n]*\n(.*?)```", md.read_text(encoding="utf-8"), flags=re.S):
            for line in block.splitlines():
                line = line.split("  #")[0].strip()
                words = shlex.split(line) if line else []
                if words and Path(words[0]).name == "qtanimator":
                    found.append((f"{md.name}: {line}", words[1:]))
    return found


COMMANDS = _command_lines()


def test_the_docs_show_command_lines() -> None:
    subcommands = {args[0] for _where, args in COMMANDS if args}
    assert {"render", "info"} <= subcommands


def _small(args: list[str], tmp_path: Path) -> list[str]:
    """The same render with a tiny size, two frames and the output under ``tmp_path``,
    keeping the kind of output (folder, pattern, GIF, video)."""
    from qtanimator.render.cli_render import _parser

    ns = _parser().parse_args(args)
    out = Path(ns.output)
    if "%" in out.name:
        target = tmp_path / "frames" / out.name
    elif out.suffix:
        target = tmp_path / f"out{out.suffix}"
    else:
        target = tmp_path / "folder"
    first = int(ns.frames.split(":")[0]) if ns.frames else 0
    small = [ns.scene, "-o", str(target), "--frames", f"{first}:{first + 1}", "--size", "64x48", "--quiet",
             "--view", ns.view] + (["--background", ns.background] if ns.background is not None else [])
    return small + (["--fps", str(ns.fps)] if ns.fps else [])


def _params() -> list[object]:
    params = []
    for where, args in COMMANDS:
        marks = [pytest.mark.gl] if args[:1] == ["render"] and "3d" in args else []
        params.append(pytest.param(args, id=where, marks=marks))
    return params


@pytest.mark.parametrize("args", _params())
def test_command_line_in_the_docs_runs(args: list[str], tmp_path: Path, qapp, monkeypatch) -> None:
    from qtanimator.cli import main

    monkeypatch.chdir(REPO)
    if args[:1] == ["export"]:
        out = tmp_path / "out.glb"
        i = args.index("-o")
        assert main([*args[:i + 1], str(out), *args[i + 2:]]) == 0
        assert out.read_bytes()[:4] == b"glTF"
        return
    if not args or args[0] not in ("render", "info"):
        # ``qtanimator [PATH]`` opens the GUI: only check what it would open.
        assert not args or Path(args[0]).exists() or args[0].startswith("-"), args
        return
    if args[0] == "info":
        assert main(args) == 0
        return
    from qtanimator.render.cli_render import _parse_frames, _parse_size, _parser, load_scene
    from qtanimator.render.export import output_kind

    ns = _parser().parse_args(args[1:])  # SystemExit on a bad option
    doc = load_scene(ns.scene)
    output_kind(ns.output)
    _parse_size(ns.size)
    _parse_frames(ns.frames, doc.frame_range)
    assert main(["render", *_small(args[1:], tmp_path)]) == 0
    assert any(p.is_file() and p.stat().st_size > 0 for p in tmp_path.rglob("*"))


# ------------------------------------------------------------------ keyboard reference
_MODS = {"Ctrl": "ControlModifier", "Shift": "ShiftModifier", "Alt": "AltModifier"}
_STANDARD = {  # QKeySequence.StandardKey → what Qt binds on Linux
    "New": {"Ctrl+N"}, "Open": {"Ctrl+O"}, "Save": {"Ctrl+S"}, "SaveAs": {"Ctrl+Shift+S"},
    "Quit": {"Ctrl+Q"}, "Undo": {"Ctrl+Z"}, "Redo": {"Ctrl+Shift+Z"},
}


def _sections() -> list[tuple[list[Path], list[str]]]:
    """(modules named in the heading, backticked tokens of the first table column)."""
    out: list[tuple[list[Path], list[str]]] = []
    for line in KEYBOARD.read_text(encoding="utf-8").splitlines():
        if line.startswith("#"):
            modules = [REPO / "qtanimator" / m for m in re.findall(r"`(ui/[\w/]+\.py)`", line)]
            out.append((modules, []))
        elif line.startswith("|") and out:
            first = line.split("|")[1]
            out[-1][1].extend(re.findall(r"`([^`]+)`", first))
    return [(m, t) for m, t in out if t]


def _bound_sequences(source: str) -> set[str]:
    seqs = set(re.findall(r'QKeySequence\("([^"]+)"\)', source))
    for body in re.findall(r'\[((?:"[^"]*",?\s?)+)\]', source):  # the timeline's key lists
        seqs.update(re.findall(r'"([^"]*)"', body))
    for name in re.findall(r"StandardKey\.(\w+)", source):
        seqs.update(_STANDARD.get(name, ()))
    seqs.update(re.findall(r'\\t([A-Z][\w+]*)"', source))  # "Frame All\tA" menu hints
    return seqs


def test_keyboard_reference_names_modules_that_exist() -> None:
    sections = _sections()
    assert len(sections) >= 6
    for modules, _tokens in sections:
        assert modules, "every section of keyboard.md names the modules it documents"
        for m in modules:
            assert m.is_file(), m


def test_every_documented_key_is_bound_in_the_code() -> None:
    for modules, tokens in _sections():
        source = "\n".join(m.read_text(encoding="utf-8") for m in modules)
        sequences = _bound_sequences(source)
        for token in tokens:
            if token in sequences:
                continue
            *mods, key = token.split("+") if token != "+" else ["+"]
            if key in _MODS and not mods:  # a modifier held with the mouse
                assert _MODS[key] in source, f"{token} is not used in {[m.name for m in modules]}"
                continue
            assert f"Qt.Key.Key_{key}" in source, f"{token}: no Key_{key} in {[m.name for m in modules]}"
            for mod in mods:
                assert _MODS[mod] in source, f"{token}: no {_MODS[mod]} in {[m.name for m in modules]}"


def test_every_key_the_code_handles_is_documented() -> None:
    documented = " ".join(t for _m, tokens in _sections() for t in tokens)
    words = set(re.split(r"[+\s]", documented))
    for path in sorted(UI.rglob("*.py")):
        source = path.read_text(encoding="utf-8")
        for key in set(re.findall(r"Qt\.Key\.Key_(\w+)", source)):
            assert key in words, f"{_rel(path)} handles Key_{key}, which docs/keyboard.md does not list"
        for seq in re.findall(r'QKeySequence\("([^"]+)"\)', source):
            assert seq in documented.split(" ") or seq in words, \
                f"{_rel(path)} binds {seq}, which docs/keyboard.md does not list"
