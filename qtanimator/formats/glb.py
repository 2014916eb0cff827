"""The GLB container of glTF 2.0: a 12-byte header, a JSON chunk and an optional BIN chunk.

::

    header: magic "glTF", version 2, total length      (3 × uint32, little endian)
    chunk:  length, type ("JSON" / "BIN\\0"), data      (data padded to 4 bytes)

The JSON chunk is padded with spaces and the BIN chunk with zeros (glTF 2.0 §4.4). Chunks of
other types are skipped, as the specification asks.
"""

from __future__ import annotations

import json
import os
import struct
from typing import Any

from qtanimator.formats.errors import FormatError

GLB_MAGIC = b"glTF"
CHUNK_JSON = 0x4E4F534A
CHUNK_BIN = 0x004E4942
HEADER = struct.Struct("<4sII")
CHUNK_HEADER = struct.Struct("<II")

__all__ = ["CHUNK_BIN", "CHUNK_JSON", "GLB_MAGIC", "build_glb", "is_glb", "parse_json_text", "read_glb"]


def is_glb(data: bytes) -> bool:
    return data[:4] == GLB_MAGIC


def read_glb(data: bytes, path: str | os.PathLike[str] | None = None) -> tuple[dict[str, Any], bytes | None]:
    """Split a GLB file into its JSON object and its BIN chunk (None when there is none)."""
    if len(data) < HEADER.size:
        raise FormatError(f"the file is {len(data)} bytes long, too short for a GLB header.", path)
    magic, version, length = HEADER.unpack_from(data, 0)
    if magic != GLB_MAGIC:
        raise FormatError("this is not a GLB file (it does not start with 'glTF').", path)
    if version != 2:
        raise FormatError(f"GLB version {version} is not supported; qtanimator reads glTF 2.0.", path)
    if length > len(data):
        raise FormatError(f"the GLB header says {length} bytes but the file has {len(data)}; "
                          "it is truncated.", path)
    if length < HEADER.size:
        raise FormatError(f"the GLB header gives an impossible length ({length}).", path)
    offset = HEADER.size
    json_obj: dict[str, Any] | None = None
    bin_chunk: bytes | None = None
    index = 0
    while offset < length:
        if offset + CHUNK_HEADER.size > length:
            raise FormatError(f"chunk {index} at byte {offset} has an incomplete header.", path)
        chunk_length, chunk_type = CHUNK_HEADER.unpack_from(data, offset)
        start = offset + CHUNK_HEADER.size
        end = start + chunk_length
        if end > length:
            raise FormatError(f"chunk {index} at byte {offset} runs past the end of the file "
                              f"({chunk_length} bytes announced).", path)
        if index == 0 and chunk_type != CHUNK_JSON:
            raise FormatError("the first GLB chunk must be the JSON chunk.", path)
        if chunk_type == CHUNK_JSON:
            if index != 0:
                raise FormatError("a GLB file has exactly one JSON chunk, first.", path)
            json_obj = parse_json_text(data[start:end], path)
        elif chunk_type == CHUNK_BIN:
            if index != 1:
                raise FormatError("the BIN chunk must directly follow the JSON chunk.", path)
            bin_chunk = bytes(data[start:end])
        # Unknown chunk types are ignored (glTF 2.0 §4.4.3.1).
        offset = end  # chunk lengths include their padding
        index += 1
    if json_obj is None:
        raise FormatError("the GLB file has no JSON chunk.", path)
    return json_obj, bin_chunk


def _reject_constant(name: str) -> Any:
    raise ValueError(f"'{name}' is not a JSON number")


def parse_json_text(data: bytes | str, path: str | os.PathLike[str] | None = None) -> dict[str, Any]:
    """Parse glTF JSON (UTF-8, BOM tolerated) into a dict; NaN and Infinity are refused."""
    try:
        text = data.decode("utf-8-sig") if isinstance(data, bytes) else data
    except UnicodeDecodeError as exc:
        raise FormatError(f"the JSON is not valid UTF-8 (byte {exc.start}).", path) from exc
    try:
        obj = json.loads(text, parse_constant=_reject_constant)
    except json.JSONDecodeError as exc:
        raise FormatError(f"the JSON is malformed: {exc.msg}.", path, exc.lineno, exc.colno) from exc
    except (ValueError, RecursionError) as exc:
        raise FormatError(f"the JSON cannot be read: {exc}.", path) from exc
    if not isinstance(obj, dict):
        raise FormatError("the glTF JSON must be an object ({ … }).", path, 1, 1)
    return obj


def build_glb(json_obj: dict[str, Any], bin_data: bytes | None) -> bytes:
    """Pack a JSON object and binary data into GLB bytes (4-byte aligned chunks)."""
    text = json.dumps(json_obj, separators=(",", ":"), allow_nan=False, ensure_ascii=False).encode("utf-8")
    text += b" " * ((-len(text)) % 4)
    parts = [CHUNK_HEADER.pack(len(text), CHUNK_JSON), text]
    if bin_data is not None:
        padded = bin_data + b"\0" * ((-len(bin_data)) % 4)
        parts += [CHUNK_HEADER.pack(len(padded), CHUNK_BIN), padded]
    body = b"".join(parts)
    return HEADER.pack(GLB_MAGIC, 2, HEADER.size + len(body)) + body
