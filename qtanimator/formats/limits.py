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
#: Bytes one base64 ``data:`` URI of a glTF may decode to (bigger buffers belong in a
#: ``.bin`` file or a ``.glb``, which are read without the base64 text in memory too).
MAX_DATA_URI_BYTES = 64 << 20

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


# -------------------------------------------------------------- text readers (_tokens.py)
#: Tokens (words, numbers, braces) of one .anim/.skel/.skin/.morph file. A token costs about
#: 60 bytes as a Python string, so this keeps the token list well under 1 GB.
MAX_TOKENS = 10_000_000

# ----------------------------------------------------------------- SVG rigs (svg_rig.py)
# svgelements does work per element that grows with what the element inherits and with
# <use> copies, so the SVG limits count the document as svgelements will expand it.
#: Elements of one SVG, counting every copy that a <use> makes.
MAX_SVG_ELEMENTS = 20_000
#: Nesting depth of elements, counting what <use> copies nest.
MAX_SVG_DEPTH = 128
#: <use> copies made while reading one SVG (a <use> inside a copied group is copied again).
MAX_SVG_USE_EXPANSIONS = 10_000
#: <use> elements that refer, through each other, to one element (a <use> of a <use> is 2).
MAX_SVG_USE_DEPTH = 16
#: Characters of any one attribute and of a <style> element (path data and images excepted).
MAX_ATTRIBUTE_BYTES = 1 << 20
#: Characters of one presentation value (fill, stroke, x, width, transform, a style
#: declaration…): svgelements parses these again for every element that inherits them.
MAX_SVG_VALUE_BYTES = 1024
#: Characters of all path data (``d`` and ``points``) of one SVG.
MAX_PATH_DATA_BYTES = 8 << 20
#: Points (coordinate pairs) in the path data of one SVG, counting every <use> copy.
MAX_PATH_POINTS = 250_000
#: Points of the shapes of one SVG after curves are flattened into line segments.
MAX_FLATTENED_POINTS = 2_000_000
#: Transform functions evaluated: every element evaluates its own transform and those of
#: all the groups (and <use>s) around it.
MAX_SVG_INHERITED_TRANSFORMS = 50_000
#: Attributes copied: every element carries its own attributes and those of the groups around it.
MAX_SVG_INHERITED_ATTRIBUTES = 5_000_000
#: Characters of style text applied: every element's style, class and id attributes and the
#: <style> rules that match it (each <use> copy applies them again).
MAX_SVG_STYLE_BYTES = 32 << 20
