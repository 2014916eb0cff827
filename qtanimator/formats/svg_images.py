"""The images of an SVG character, checked before QtSvg sees them: QtSvg only ever gets
``data:`` URIs.

QtSvg opens whatever file an ``<image>`` names (``href`` or ``xlink:href``, absolute, or
relative to the *process's* current folder), a named pipe included, on which ``open`` blocks
forever. So every joint document (:mod:`qtanimator.formats.svg_joint_documents`) passes through
:meth:`ImageGate.clean` before it leaves the reader: each ``<image>`` element, wherever it is
(``<defs>``, reached through ``<use>``, in a pattern or mask), has its reference

- to a file: resolved against the SVG's own folder, read through
  :func:`qtanimator.formats.file_gate.checked_regular_file` (inside the SVG's folder with
  symbolic links resolved, a regular file, at most ``MAX_LINKED_FILE_BYTES``), and inlined;
- a ``data:`` URI: decoded;

and kept, as a base64 ``data:`` URI, only when its bytes are a PNG, JPEG, GIF, WebP or SVG
image (by their magic bytes) of at most ``MAX_IMAGE_PIXELS`` pixels (read from the header)
and the character's images stay within ``MAX_SVG_IMAGE_BYTES`` / ``MAX_SVG_IMAGE_PIXELS``
counting every copy in every joint document. An SVG image is cleaned the same way (its own
images resolved against its own folder, still inside the character's folder), two levels
deep at most. Anything else (outside the folder, missing, a pipe or device, too big, a remote
URL, another format) loses its reference, so the image is not drawn and the rest of the art
is; the character carries one warning per reference, which names the reference and never
quotes a file's contents. Other elements keep only ``#id`` references (QtSvg follows no
other, but nothing else needs one).
"""

from __future__ import annotations

import base64
import binascii
import re
import urllib.parse
import xml.etree.ElementTree as ET
from pathlib import Path

from qtanimator.formats.errors import FormatError
from qtanimator.formats.file_gate import (
    MAX_IMAGE_PIXELS,
    MAX_LINKED_FILE_BYTES,
    checked_regular_file,
    image_kind,
    image_pixels,
    mime_type,
    resolve_reference,
    short,
)

_SVG_NS = "http://www.w3.org/2000/svg"
_XLINK_HREF = "{http://www.w3.org/1999/xlink}href"
#: Bytes of image data that one character's joint documents hold, every copy counted (an
#: image in ``<defs>`` is copied into each joint's document).
MAX_SVG_IMAGE_BYTES = 128 << 20
#: Pixels of the images of one character's joint documents, every copy counted (QtSvg decodes
#: each copy: 4 bytes a pixel).
MAX_SVG_IMAGE_PIXELS = 128_000_000
#: SVG images inside SVG images inside the character: deeper ones lose their images.
MAX_IMAGE_NESTING = 2

_LENGTH = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*(px|pt|pc|mm|cm|in)?\s*$")
_PX = {None: 1.0, "px": 1.0, "pt": 1.25, "pc": 15.0, "mm": 3.78, "cm": 37.8, "in": 96.0}


def _local(tag: object) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


class ImageGate:
    """Cleans the ``<image>`` references of one character's SVG documents (see the module)."""

    def __init__(self, folder: Path | None) -> None:
        #: The character's folder: every file an image names must lie inside it.
        self.folder = folder
        #: One sentence per reference that was dropped.
        self.warnings: list[str] = []
        self._warned: set[str] = set()
        self._done: dict[tuple[str, str, int], tuple[str, int, int] | None] = {}
        self.bytes = 0
        self.pixels = 0

    def clean(self, root: ET.Element, base: Path | None = None, depth: int = 0) -> None:
        """Rewrite ``root``'s images in place; ``base`` is the folder relative references
        start from (the character's folder by default)."""
        base = self.folder if base is None else base
        for el in root.iter():
            refs = [k for k in el.attrib if _local(k) == "href"]
            if _local(el.tag) != "image":
                for k in refs:
                    if not el.attrib[k].lstrip().startswith("#"):
                        del el.attrib[k]
                continue
            value = el.get("href") or el.get(_XLINK_HREF) or next((el.attrib[k] for k in refs if el.attrib[k]), "")
            for k in refs:
                del el.attrib[k]
            value = value.strip()
            if not value:
                continue
            inlined = self._inline(value, base, depth)
            if inlined is not None:
                el.set(_XLINK_HREF, inlined)

    # ---------------------------------------------------------------------------- private
    def _inline(self, value: str, base: Path | None, depth: int) -> str | None:
        key = (value, str(base), depth)
        if key not in self._done:
            try:
                self._done[key] = self._checked(value, base, depth)
            except FormatError as exc:
                self._done[key] = None
                self._warn(value, str(exc.args[0] if exc.args else exc))
        done = self._done[key]
        if done is None:
            return None
        uri, size, pixels = done
        if self.bytes + size > MAX_SVG_IMAGE_BYTES:
            self._warn(value, f"the character's images would hold more than qtanimator's limit of "
                       f"{MAX_SVG_IMAGE_BYTES:,} bytes (MAX_SVG_IMAGE_BYTES, every copy counted).")
            return None
        if self.pixels + pixels > MAX_SVG_IMAGE_PIXELS:
            self._warn(value, f"the character's images would have more than qtanimator's limit of "
                       f"{MAX_SVG_IMAGE_PIXELS:,} pixels (MAX_SVG_IMAGE_PIXELS, every copy counted).")
            return None
        self.bytes += size
        self.pixels += pixels
        return uri

    def _warn(self, value: str, reason: str) -> None:
        if value in self._warned:
            return
        self._warned.add(value)
        what = "an embedded image" if value.startswith("data:") else f"the image {short(value)}"
        reason = reason.rstrip(".")
        if reason.startswith(short(value)):
            reason = "it" + reason[len(short(value)):]
        self.warnings.append(f"{what} is not drawn: {reason[:1].lower() + reason[1:]}.")

    def _checked(self, value: str, base: Path | None, depth: int) -> tuple[str, int, int]:
        """The data URI for one reference, its size in bytes and its pixels."""
        if value.startswith("data:"):
            data = _data_uri_bytes(value)
            source_base = base
        else:
            if self.folder is None or base is None:
                raise FormatError("the SVG has no folder, so it may not name files.")
            target = resolve_reference(value, base, self.folder)
            data = checked_regular_file(target, self.folder, MAX_LINKED_FILE_BYTES, reference=value)
            source_base = target.parent
        kind = image_kind(data)
        if kind is None:
            raise FormatError("it is not a PNG, JPEG, GIF, WebP or SVG image.")
        if kind == "svg":
            data, pixels = self._nested_svg(data, source_base, depth)
        else:
            width, height = image_pixels(data)
            pixels = width * height
        if pixels > MAX_IMAGE_PIXELS:
            raise FormatError(f"it has more than qtanimator's limit of {MAX_IMAGE_PIXELS:,} pixels for one "
                              "image (MAX_IMAGE_PIXELS).")
        uri = f"data:{mime_type(kind)};base64," + base64.b64encode(data).decode("ascii")
        return uri, len(uri), pixels

    def _nested_svg(self, data: bytes, base: Path | None, depth: int) -> tuple[bytes, int]:
        from qtanimator.formats._svg_budget import check_budget

        try:
            check_budget(data, None)
            root = ET.fromstring(data)
        except FormatError as exc:
            raise FormatError(f"it is an SVG image beyond a limit ({exc.args[0] if exc.args else exc})") from None
        except Exception:  # noqa: BLE001 - nothing else may escape a reader
            raise FormatError("it is an SVG image that cannot be read.") from None
        pixels = _svg_pixels(root)
        for el in root.iter():  # QtSvg reads unprefixed SVG elements; ElementTree would write ns0:
            if isinstance(el.tag, str) and el.tag.startswith(f"{{{_SVG_NS}}}"):
                el.tag = el.tag[len(_SVG_NS) + 2:]
        root.set("xmlns", _SVG_NS)
        if depth + 1 >= MAX_IMAGE_NESTING:
            _drop_images(root)
        else:
            self.clean(root, base, depth + 1)
        return ET.tostring(root), pixels


def _drop_images(root: ET.Element) -> None:
    for el in root.iter():
        for k in [k for k in el.attrib if _local(k) == "href"]:
            if _local(el.tag) == "image" or not el.attrib[k].lstrip().startswith("#"):
                del el.attrib[k]


def _data_uri_bytes(value: str) -> bytes:
    head, sep, payload = value.partition(",")
    if not sep:
        raise FormatError("it is a data URI without data.")
    if len(payload) > MAX_LINKED_FILE_BYTES * 4 // 3 + 8:
        raise FormatError(f"it is a data URI of more than qtanimator's limit of {MAX_LINKED_FILE_BYTES:,} bytes.")
    if head.lower().replace(" ", "").endswith(";base64"):
        try:
            return base64.b64decode("".join(payload.split()), validate=True)
        except (binascii.Error, ValueError):
            raise FormatError("it is a data URI with invalid base64 data.") from None
    data = urllib.parse.unquote_to_bytes(payload)
    if len(data) > MAX_LINKED_FILE_BYTES:
        raise FormatError(f"it is a data URI of more than qtanimator's limit of {MAX_LINKED_FILE_BYTES:,} bytes.")
    return data


def _svg_pixels(root: ET.Element) -> int:
    """The pixels QtSvg gives an SVG image by default (its width × height, else its viewBox's)."""
    box = [v for v in re.split(r"[\s,]+", (root.get("viewBox") or "").strip()) if v]
    sizes: list[float] = []
    for i, key in enumerate(("width", "height")):
        m = _LENGTH.match(root.get(key) or "")
        if m:
            sizes.append(float(m.group(1)) * _PX[m.group(2)])
        else:
            try:
                sizes.append(float(box[2 + i]) if len(box) == 4 else 100.0)
            except ValueError:
                sizes.append(100.0)
    w, h = sizes
    if not (w < 1e9 and h < 1e9):  # NaN, infinity or absurd
        return 1 << 62
    return int(max(w, 1.0) * max(h, 1.0))
