"""What a reader accepts at most: the limits that keep a hostile file within time and memory.

Every reader checks its input against these before it allocates or loops, and refuses a
file beyond them with a :class:`FormatError` that names the limit (:func:`exceeded`).
Limits are either global ceilings or proportional to the input (a file may not expand to
more than ``MAX_EXPANSION`` times its own bytes). docs/formats.md lists them.
"""

from __future__ import annotations

import os

from qtanimator.formats.errors import FormatError

# ----------------------------------------------------------------------- global ceilings
#: Bytes of numeric data a reader may decode from one file (accessors, vertex arrays).
MAX_DECODED_BYTES = 1 << 30
#: Vertices of all meshes of one file.
MAX_VERTICES = 10_000_000
#: Joints (nodes that a skin uses) of one skeleton.
MAX_JOINTS = 10_000
#: Nodes of one glTF scene.
MAX_NODES = 100_000

# --------------------------------------------------------------------- proportional
#: A file's decoded numeric data may be at most this many times its own bytes (plus
#: ``MIN_DECODED_ALLOWANCE``), so a small file that points many accessors at one buffer
#: view cannot expand into gigabytes.
MAX_EXPANSION = 64
MIN_DECODED_ALLOWANCE = 64 << 20


def decoded_budget(input_bytes: int) -> int:
    """Bytes of decoded data allowed for an input of ``input_bytes``."""
    return min(MAX_DECODED_BYTES, MIN_DECODED_ALLOWANCE + MAX_EXPANSION * max(input_bytes, 0))


def exceeded(what: str, limit: int | str, path: str | os.PathLike[str] | None = None) -> FormatError:
    """The error for a file beyond a limit: ``"the file has more than 10000 joints (the
    limit for one skeleton)."``-style sentences name what and the limit."""
    return FormatError(f"{what} exceeds qtanimator's limit of {limit}; the file is refused.", path)
