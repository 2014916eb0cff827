"""Issue 31, part 1, the SVG rows: QtSvg gets only ``data:`` URIs, so an ``<image>`` that names
a file outside the character's folder, a named pipe or a device is never opened and never drawn,
an image inside the folder is drawn, and relative references start from the SVG's folder, not
the current folder. Real files, real QtSvg, in a subprocess (under strace when it is installed,
which sees QtSvg's own ``open`` calls as well as Python's)."""

from __future__ import annotations

import json
import os
import shutil
import signal
import struct
import subprocess
import sys
import textwrap
import time
import zlib
from pathlib import Path

import pytest

from qtanimator.formats.errors import FormatError
from qtanimator.formats.file_gate import checked_regular_file, image_kind, image_pixels, resolve_reference
from qtanimator.formats.svg_rig import load_character, parse_character

RED, GREEN, GREY = (255, 0, 0), (0, 255, 0), (128, 128, 128)

#: Loads a character, renders its joints with QtSvg into a 40×40 frame and prints the frame's
#: pixels, the warnings, the files Python opened (audit hook) and the seconds it took.
_RENDER = textwrap.dedent("""
    import json, os, sys, time
    opened = []
    def audit(event, args):
        if event == "open" and isinstance(args[0], (str, bytes)):
            name = os.fsdecode(args[0])
            if not name.endswith((".py", ".pyc", ".so")):
                opened.append(os.path.realpath(name))
    from PySide6.QtCore import QRectF, QByteArray
    from PySide6.QtGui import QGuiApplication, QImage, QPainter
    from PySide6.QtSvg import QSvgRenderer
    from qtanimator.formats.svg_rig import load_character
    app = QGuiApplication(sys.argv[:1])
    sys.addaudithook(audit)
    started = time.monotonic()
    character = load_character(sys.argv[1])
    image = QImage(40, 40, QImage.Format.Format_RGB32)
    image.fill(0xFFFFFFFF)
    painter = QPainter(image)
    for joint in character.joints:
        QSvgRenderer(QByteArray(joint.svg.encode())).render(painter, QRectF(0, 0, 1, 1))
    painter.end()
    seconds = time.monotonic() - started
    pixels = [image.pixel(x, y) & 0xFFFFFF for y in range(40) for x in range(40)]
    print(json.dumps({"pixels": pixels, "warnings": character.warnings, "opened": opened,
                      "seconds": seconds}))
""")


def _png(path: Path, colour: tuple[int, int, int]) -> Path:
    from PIL import Image

    Image.new("RGB", (8, 8), colour).save(path)
    return path


def _svg(folder: Path, image: str | None, name: str = "character.svg") -> Path:
    """A rig of one joint: a grey square, the image over its middle, the pivot."""
    path = folder / name
    path.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
        'width="40" height="40"><g id="body"><rect width="40" height="40" fill="#808080"/>'
        f'{image or ""}<circle cx="2" cy="2" r="1"/></g></svg>')
    return path


def _image(href: str, attribute: str = "href") -> str:
    return f'<image {attribute}="{href}" x="10" y="10" width="20" height="20"/>'


def _render(svg: Path, cwd: Path) -> tuple[dict[str, object], list[str]]:
    """The subprocess's report and the files it opened as strace saw them ([] without strace)."""
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")
    cmd = [sys.executable, "-c", _RENDER, str(svg)]
    trace = cwd / "strace.txt"
    if shutil.which("strace") and subprocess.run(["strace", "-o", os.devnull, "true"],
                                                 capture_output=True).returncode == 0:
        cmd = ["strace", "-f", "-qq", "-e", "trace=open,openat,openat2", "-o", str(trace), *cmd]
    out = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-3000:]
    report = json.loads(out.stdout.strip().splitlines()[-1])
    traced = trace.read_text().splitlines() if trace.exists() else []
    return report, traced


def _colour(report: dict[str, object], x: int = 20, y: int = 20) -> tuple[int, int, int]:
    v = report["pixels"][y * 40 + x]  # type: ignore[index]
    return (v >> 16) & 255, (v >> 8) & 255, v & 255


@pytest.fixture
def scene(tmp_path: Path) -> dict[str, Path]:
    """The character's folder ``asset`` (with ``inside.png``, red, and a FIFO), a green
    ``outside.png`` beside it, and another current folder holding its own, green,
    ``inside.png`` and ``cwd_only.png``."""
    asset = tmp_path / "asset"
    asset.mkdir()
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    _png(asset / "inside.png", RED)
    _png(tmp_path / "outside.png", GREEN)
    _png(elsewhere / "inside.png", GREEN)
    _png(elsewhere / "cwd_only.png", GREEN)
    os.mkfifo(asset / "pipe.png")
    return {"root": tmp_path, "asset": asset, "cwd": elsewhere}


def _never_opened(traced: list[str], report: dict[str, object], *paths: str) -> None:
    for p in paths:
        real = os.path.realpath(p)
        assert real not in report["opened"], f"Python opened {p}"  # type: ignore[operator]
        assert not any(f'"{p}"' in line or f'"{real}"' in line for line in traced), f"opened {p}"


@pytest.mark.parametrize("case", ["absolute", "dotdot", "fifo", "dev_zero", "cwd_relative", "use_absolute",
                                  "xlink_dotdot"])
def test_an_image_outside_the_folder_is_neither_opened_nor_drawn(scene: dict[str, Path], case: str) -> None:
    outside = str(scene["root"] / "outside.png")
    markup = {
        "absolute": _image(outside),
        "dotdot": _image("../outside.png"),
        "fifo": _image("pipe.png"),
        "dev_zero": _image("/dev/zero"),
        "cwd_relative": _image("cwd_only.png"),
        "use_absolute": f'<defs><image id="im" xlink:href="{outside}" x="10" y="10" width="20" '
                        'height="20"/></defs><use xlink:href="#im"/>',
        "xlink_dotdot": _image("../outside.png", "xlink:href"),
    }[case]
    report, traced = _render(_svg(scene["asset"], markup), scene["cwd"])
    plain, _ = _render(_svg(scene["asset"], None, "plain.svg"), scene["cwd"])
    assert report["pixels"] == plain["pixels"]  # nothing of the image is drawn
    assert _colour(report) == GREY
    _never_opened(traced, report, outside, str(scene["asset"] / "pipe.png"), "/dev/zero",
                  str(scene["cwd"] / "cwd_only.png"), str(scene["cwd"] / "inside.png"))
    dropped = [w for w in report["warnings"] if "is not drawn" in w]  # type: ignore[union-attr]
    assert len(dropped) == 1, report["warnings"]
    assert report["seconds"] < 5  # type: ignore[operator]


def test_a_fifo_image_does_not_hang_the_reader(scene: dict[str, Path]) -> None:
    started = time.monotonic()
    character = load_character(_svg(scene["asset"], _image("pipe.png")))
    assert time.monotonic() - started < 5
    assert any('"pipe.png"' in w and "not a regular file" in w for w in character.warnings)


@pytest.mark.parametrize("markup", [
    _image("inside.png"),
    _image("inside.png", "xlink:href"),
    '<defs><image id="im" href="inside.png" x="10" y="10" width="20" height="20"/></defs><use href="#im"/>',
], ids=["href", "xlink", "use"])
def test_an_image_inside_the_folder_is_drawn_relative_to_the_svg_not_the_cwd(
        scene: dict[str, Path], markup: str) -> None:
    report, traced = _render(_svg(scene["asset"], markup), scene["cwd"])
    assert _colour(report) == RED  # the asset's inside.png, not the current folder's green one
    assert _colour(report, 3, 35) == GREY
    assert not [w for w in report["warnings"] if "is not drawn" in w]  # type: ignore[union-attr]
    _never_opened(traced, report, str(scene["cwd"] / "inside.png"))


def test_the_qtsvg_documents_hold_only_data_uris(scene: dict[str, Path]) -> None:
    body = (_image("inside.png") + _image("../outside.png") + _image("http://example.com/a.png")
            + _image("/dev/zero", "xlink:href"))
    character = load_character(_svg(scene["asset"], body))
    svg = character.joints[0].svg
    assert svg is not None
    assert "outside" not in svg and "example.com" not in svg and "/dev/zero" not in svg
    assert svg.count("data:image/png;base64,") == 1
    dropped = [w for w in character.warnings if "is not drawn" in w]
    assert len(dropped) == 3, dropped
    assert all("PNG" not in w for w in dropped)  # names the reference, never the contents


def _png_header(width: int, height: int) -> bytes:
    """A PNG whose header declares ``width`` × ``height`` (no pixel data: only the size is read)."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", b"") + chunk(b"IEND", b"")


def test_image_pixels_are_capped_from_the_header(tmp_path: Path) -> None:
    import base64

    big = base64.b64encode(_png_header(10_000, 10_000)).decode()
    (tmp_path / "big.png").write_bytes(_png_header(9000, 9000))
    body = _image(f"data:image/png;base64,{big}") + _image("big.png")
    character = load_character(_svg(tmp_path, body))
    dropped = [w for w in character.warnings if "pixels" in w]
    assert len(dropped) == 2, character.warnings
    assert "data:image" not in (character.joints[0].svg or "")
    assert image_pixels(_png_header(300, 200)) == (300, 200)


def test_an_svg_image_is_cleaned_too(scene: dict[str, Path]) -> None:
    inner = scene["asset"] / "sub"
    inner.mkdir()
    (inner / "nested.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="8" height="8">'
                                      '<image href="../../outside.png" width="8" height="8"/>'
                                      '<image href="../inside.png" width="8" height="8"/></svg>')
    character = load_character(_svg(scene["asset"], _image("sub/nested.svg")))
    svg = character.joints[0].svg or ""
    assert svg.count("data:image/svg+xml;base64,") == 1
    assert any('"../../outside.png"' in w for w in character.warnings)
    assert not any('"../inside.png"' in w for w in character.warnings)  # sub/../inside.png is inside


def test_no_folder_no_files() -> None:
    data = _svg_bytes(_image("/etc/passwd"))
    character = parse_character(data, "x")
    assert "/etc/passwd" not in (character.joints[0].svg or "")
    assert any("no folder" in w for w in character.warnings)


def _svg_bytes(image: str) -> bytes:
    return ('<svg xmlns="http://www.w3.org/2000/svg" width="40" height="40"><g id="body">'
            f'<rect width="40" height="40"/>{image}<circle cx="2" cy="2" r="1"/></g></svg>').encode()


# ------------------------------------------------------------------------- the gate itself
def test_gate_reads_a_regular_file_inside(tmp_path: Path) -> None:
    (tmp_path / "a.bin").write_bytes(b"abc")
    assert checked_regular_file(tmp_path / "a.bin", tmp_path, 10) == b"abc"


def test_gate_refuses_without_opening(tmp_path: Path) -> None:
    folder = tmp_path / "in"
    folder.mkdir()
    (tmp_path / "secret.txt").write_text("TOP SECRET WORDS")
    (folder / "link.txt").symlink_to(tmp_path / "secret.txt")
    os.mkfifo(folder / "fifo")
    (folder / "big.bin").write_bytes(b"\0" * 101)
    (folder / "dir").mkdir()
    for name, why in [("link.txt", "outside"), ("fifo", "not a regular file"), ("big.bin", "limit of 100"),
                      ("dir", "a folder"), ("missing", "does not exist")]:
        with pytest.raises(FormatError, match=why) as info:
            checked_regular_file(folder / name, folder, 100, reference=name)
        assert "SECRET" not in str(info.value)
    with pytest.raises(FormatError, match="outside"):
        checked_regular_file("/dev/zero", folder, 100)
    with pytest.raises(FormatError, match="outside"):
        resolve_reference("../secret.txt", folder, folder)
    with pytest.raises(FormatError, match="outside"):
        resolve_reference("%2e%2e/secret.txt", folder, folder)
    with pytest.raises(FormatError, match="not a local file"):
        resolve_reference("https://example.com/x.png", folder, folder)


def test_image_kinds() -> None:
    assert image_kind(_png_header(1, 1)) == "png"
    assert image_kind(b"\xff\xd8\xff\xe0rest") == "jpeg"
    assert image_kind(b"GIF89a....") == "gif"
    assert image_kind(b"RIFF\0\0\0\0WEBPVP8 ") == "webp"
    assert image_kind(b'<?xml version="1.0"?>\n<!-- c -->\n<svg xmlns="x">') == "svg"
    assert image_kind(b"\x1f\x8b\x08") is None  # gzip (svgz)
    assert image_kind(b"root:x:0:0:root:/root:/bin/bash") is None


# -------------------------------------------------------------------------------- render
def test_render_of_a_character_with_hostile_images_exits_0_and_stops_on_sigterm(scene: dict[str, Path]) -> None:
    body = (_image("pipe.png") + _image("/dev/zero") + _image("../outside.png") + _image("inside.png"))
    svg = _svg(scene["asset"], body)
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")
    cmd = [sys.executable, "-m", "qtanimator", "render", str(svg), "--size", "64x48", "--quiet", "--jobs", "1"]
    done = subprocess.run([*cmd, "-o", str(scene["cwd"] / "frames"), "--frames", "0:2"], cwd=scene["cwd"],
                          env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-3000:]
    assert len(list((scene["cwd"] / "frames").glob("*.png"))) == 3
    proc = subprocess.Popen([*cmd, "-o", str(scene["cwd"] / "long"), "--frames", "0:100000"], cwd=scene["cwd"],
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not list((scene["cwd"] / "long").glob("*.png")):
            assert proc.poll() is None, proc.stderr.read().decode() if proc.stderr else ""
            time.sleep(0.1)
        assert list((scene["cwd"] / "long").glob("*.png")), "the render wrote no frame"
        proc.send_signal(signal.SIGTERM)
        started = time.monotonic()
        _, err = proc.communicate(timeout=15)
        assert time.monotonic() - started < 10
        assert proc.returncode in (128 + signal.SIGTERM, -signal.SIGTERM), (proc.returncode, err[-2000:])
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def _limit_memory() -> None:
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))


def test_an_embedded_image_used_many_times_is_not_decoded_per_copy(tmp_path: Path) -> None:
    """svgelements decodes an image's data URI again for every <use> copy; it is given none."""
    import base64

    payload = base64.b64encode(_png_header(64, 64) + b"\0" * (4 << 20)).decode()
    uses = "".join(f'<use xlink:href="#im" x="{i % 40}"/>' for i in range(2000))
    (tmp_path / "many.svg").write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="40" '
        f'height="40"><defs><image id="im" xlink:href="data:image/png;base64,{payload}" width="4" '
        f'height="4"/></defs><g id="body"><rect width="40" height="40"/>{uses}<circle cx="2" cy="2" r="1"/>'
        '</g></svg>')
    child = ("import sys; from qtanimator.formats.svg_rig import load_character; "
             "c = load_character(sys.argv[1]); print(len(c.joints), (c.joints[0].svg or '').count('data:image/png'))")
    done = subprocess.run([sys.executable, "-c", child, str(tmp_path / "many.svg")], capture_output=True,
                          text=True, timeout=60, preexec_fn=_limit_memory)
    assert done.returncode == 0, done.stderr[-3000:]
    assert done.stdout.split() == ["1", "1"]  # one joint, its document holds the image once
