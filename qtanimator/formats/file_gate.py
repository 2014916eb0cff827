"""One gate for the files that a file names: what a reader may open on a file's word.

An asset (an SVG character, a skin, a glTF, a project) may name other files: images, textures,
companions, buffers. Such a name comes from the file, not from the user, so it is trusted no
further than the asset's own folder. :func:`checked_regular_file` is the one way to read such a
file: the name is resolved against the folder the asset gives (``..``, percent-escapes and
symbolic links resolved), and the file must

- lie inside ``folder`` (the asset's folder, symbolic links resolved on both sides);
- be a regular file: ``os.stat`` is asked *before* anything is opened, so a named pipe (which
  would block ``open`` forever) or a device (``/dev/zero`` never ends) is never opened; the
  file is then opened non-blocking and checked again on the open descriptor (same file, still
  regular), so swapping it for a pipe in between does not help;
- hold at most ``max_bytes`` bytes (read once, at most ``max_bytes + 1`` bytes).

Anything else is a :class:`FormatError` that names the reference and the rule, never the
file's contents. :func:`image_kind` and :func:`image_pixels` tell an image by its first bytes
and measure its size from its header alone (nothing is decoded), for the image budgets.

Qt-free: the SVG reader inlines the images it checked as ``data:`` URIs
(:mod:`qtanimator.formats.svg_images`), so QtSvg never opens a file itself.
"""

from __future__ import annotations

import io
import os
import re
import stat
import urllib.parse
import warnings
from pathlib import Path

from qtanimator.formats.errors import FormatError

#: Bytes of one file that an asset names (an SVG's image, and later textures and companions).
MAX_LINKED_FILE_BYTES = 32 << 20
#: Pixels (width × height, from the header) of one image an asset names or embeds.
MAX_IMAGE_PIXELS = 64_000_000

_MIME = {"png": "image/png", "jpeg": "image/jpeg", "gif": "image/gif", "webp": "image/webp",
         "svg": "image/svg+xml"}
_XML_START = re.compile(rb"\A(?:\xef\xbb\xbf)?\s*(?:<\?xml[^>]{0,200}\?>\s*)?(?:<!--.{0,4000}?-->\s*)*"
                        rb"(?:<!DOCTYPE[^>\[]{0,400}>\s*)?<(?:[A-Za-z_][\w.-]{0,40}:)?svg[\s>/]", re.DOTALL)


def short(reference: str, limit: int = 80) -> str:
    """A reference as an error may quote it: printable, at most ``limit`` characters."""
    text = reference if len(reference) <= limit else reference[:limit - 1] + "…"
    return repr(text) if not text.isprintable() else f'"{text}"'


def resolve_reference(reference: str, base: Path, folder: Path) -> Path:
    """The file that ``reference`` (a relative or absolute path, or a ``file:`` URL, with
    percent-escapes) names, relative to ``base``; FormatError unless it lies inside ``folder``
    once ``..`` and symbolic links are resolved. Nothing is opened."""
    parsed = urllib.parse.urlsplit(reference)
    if parsed.scheme.lower() == "file":
        name = urllib.parse.unquote(parsed.path)
    elif parsed.scheme and len(parsed.scheme) > 1:
        raise FormatError(f"{short(reference)} is not a local file (only files beside the asset are read).")
    else:
        name = urllib.parse.unquote(reference)
    try:
        inside = folder.resolve(strict=False)
        target = (base / name).resolve(strict=False)
    except (OSError, ValueError, RuntimeError):  # a NUL byte, a symbolic-link loop
        raise FormatError(f"{short(reference)} is not a usable file name.") from None
    if not target.is_relative_to(inside):
        raise FormatError(f"{short(reference)} lies outside the asset's folder; qtanimator reads only "
                          "files beside the asset or in folders below it.")
    return target


def checked_regular_file(path: str | os.PathLike[str], folder: str | os.PathLike[str], max_bytes: int,
                         reference: str | None = None) -> bytes:
    """The bytes of ``path`` after the gate's checks (see the module's docstring).

    ``path`` may be relative to the current folder only if ``folder`` is too; readers pass
    :func:`resolve_reference`'s result. ``reference`` is how the asset named the file, quoted
    in errors (default: the path)."""
    name = short(reference if reference is not None else os.fspath(path))
    try:
        inside = Path(folder).resolve(strict=False)
        target = Path(path).resolve(strict=False)
    except (OSError, ValueError, RuntimeError):
        raise FormatError(f"{name} is not a usable file name.") from None
    if not target.is_relative_to(inside):
        raise FormatError(f"{name} lies outside the asset's folder; qtanimator reads only files beside "
                          "the asset or in folders below it.")
    try:
        before = os.stat(target)
    except FileNotFoundError:
        raise FormatError(f"{name} does not exist.") from None
    except (OSError, ValueError) as exc:
        raise FormatError(f"{name} cannot be read ({getattr(exc, 'strerror', None) or type(exc).__name__}).") \
            from None
    if not stat.S_ISREG(before.st_mode):
        what = "a folder" if stat.S_ISDIR(before.st_mode) else "a pipe, a device or a socket"
        raise FormatError(f"{name} is {what}, not a regular file; it is not opened.")
    if before.st_size > max_bytes:
        raise FormatError(f"{name} has {before.st_size:,} bytes, more than qtanimator's limit of "
                          f"{max_bytes:,} bytes for a file an asset names.")
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0) | \
        getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(target, flags)
    except OSError as exc:
        raise FormatError(f"{name} cannot be read ({exc.strerror or type(exc).__name__}).") from None
    try:
        now = os.fstat(fd)
        if not stat.S_ISREG(now.st_mode) or (now.st_dev, now.st_ino) != (before.st_dev, before.st_ino):
            raise FormatError(f"{name} changed while it was being opened; it is not read.")
        with io.FileIO(fd, "rb", closefd=False) as fh:
            data = fh.read(max_bytes + 1) or b""
    except OSError as exc:
        raise FormatError(f"{name} cannot be read ({exc.strerror or type(exc).__name__}).") from None
    finally:
        os.close(fd)
    if len(data) > max_bytes:
        raise FormatError(f"{name} has more than qtanimator's limit of {max_bytes:,} bytes for a file an "
                          "asset names.")
    return data


def image_kind(data: bytes) -> str | None:
    """``"png"``, ``"jpeg"``, ``"gif"``, ``"webp"`` or ``"svg"`` by the first bytes; None for
    anything else (other image formats, gzip-compressed SVG, text, …)."""
    if data.startswith(b"\x89PNG\r\n\x1a\n"):
        return "png"
    if data.startswith(b"\xff\xd8\xff"):
        return "jpeg"
    if data.startswith((b"GIF87a", b"GIF89a")):
        return "gif"
    if len(data) >= 12 and data.startswith(b"RIFF") and data[8:12] == b"WEBP":
        return "webp"
    if _XML_START.match(data[:8192]):
        return "svg"
    return None


def mime_type(kind: str) -> str:
    """The media type of an :func:`image_kind`."""
    return _MIME[kind]


def image_pixels(data: bytes) -> tuple[int, int]:
    """Width and height of a PNG, JPEG, GIF or WebP from its header (no pixel is decoded);
    FormatError when the header cannot be read."""
    try:
        from PIL import Image
    except ImportError:  # pragma: no cover - pillow is a dependency
        raise FormatError("images cannot be measured (pillow is not installed).") from None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # DecompressionBombWarning: the caller has its own limit
            with Image.open(io.BytesIO(data)) as im:
                width, height = im.size
    except Image.DecompressionBombError:
        return (1 << 31, 1)  # beyond any limit of ours
    except Exception:  # noqa: BLE001 - a damaged header is an unreadable image, nothing else
        raise FormatError("the image's header cannot be read.") from None
    return int(width), int(height)
