"""The bytes of a glTF's buffers: the GLB binary chunk, base64 data URIs and external
files, which must lie inside the glTF's folder."""

from __future__ import annotations

import base64
import binascii
import urllib.parse
from pathlib import Path
from typing import Any

from qtanimator.formats._tokens import read_bytes
from qtanimator.formats.errors import FormatError
from qtanimator.formats.gltf.accessors import Reader, short
from qtanimator.formats.limits import MAX_DATA_URI_BYTES, exceeded


def load_buffers(doc: dict[str, Any], bin_chunk: bytes | None, base: Path | None,
                 path: str | None) -> list[bytes]:
    """Every buffer's bytes, cut to its ``byteLength``."""
    reader = Reader(doc, [], path)
    out: list[bytes] = []
    for i, buf in enumerate(reader.collection("buffers")):
        where = f"buffers[{i}]"
        length = reader.integer(buf, "byteLength", where, required=True, minimum=1) or 0
        uri = buf.get("uri")
        if uri is None:
            if i != 0 or bin_chunk is None:
                raise FormatError(f"{where} has no uri and there is no GLB binary chunk for it.", path)
            data = bin_chunk
        elif not isinstance(uri, str):
            raise FormatError(f"{where}.uri must be a string.", path)
        else:
            data = read_uri(uri, base, where, path)
        if len(data) < length:
            raise FormatError(f"{where} should hold {length} bytes but has only {len(data)}.", path)
        out.append(data[:length])
    return out


def read_uri(uri: str, base: Path | None, where: str, path: str | None) -> bytes:
    """The bytes a buffer or image ``uri`` names: a base64 data URI or a file in ``base``."""
    if uri.startswith("data:"):
        head, sep, payload = uri.partition(",")
        if not sep or not head.endswith(";base64"):
            raise FormatError(f"{where}.uri is a data URI that is not base64 encoded.", path)
        if len(payload) // 4 * 3 > MAX_DATA_URI_BYTES:
            raise exceeded(f"{where}.uri, a data URI of {len(payload) // 4 * 3:,} bytes",
                           f"{MAX_DATA_URI_BYTES:,} bytes (MAX_DATA_URI_BYTES)", path)
        try:
            return base64.b64decode(payload, validate=True)
        except (binascii.Error, ValueError) as exc:
            raise FormatError(f"{where}.uri holds invalid base64 data.", path) from exc
    if base is None:
        raise FormatError(f"{where} refers to an external file {short(uri)} but the glTF has no folder.", path)
    parsed = urllib.parse.urlparse(uri)
    if parsed.scheme and len(parsed.scheme) > 1:
        raise FormatError(f"{where}.uri {short(uri)} is not a local file.", path)
    target = contained_path(base, uri, where, path)
    try:
        return read_bytes(target)
    except (OSError, ValueError) as exc:  # FormatError too: a folder, a device, a missing file
        raise FormatError(f"{where} refers to {short(uri)}, which cannot be read.", path) from exc


def contained_path(base: Path, uri: str, where: str, path: str | None) -> Path:
    """The file a relative ``uri`` names inside ``base`` (the glTF's folder), after
    percent-escapes, ``..`` and symbolic links are resolved; FormatError when it lies
    outside that folder (an absolute path, ``../``, a link pointing out)."""
    try:
        folder = base.resolve(strict=False)
        target = (folder / urllib.parse.unquote(uri)).resolve(strict=False)
    except (OSError, ValueError, RuntimeError) as exc:  # a NUL byte, a symlink loop
        raise FormatError(f"{where}.uri {short(uri)} is not a usable file name.", path) from exc
    if not target.is_relative_to(folder):
        raise FormatError(f"{where}.uri {short(uri)} points outside the glTF's folder; qtanimator "
                          "reads only files beside the glTF or in folders below it.", path)
    return target
