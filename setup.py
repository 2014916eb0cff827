"""PyPI's long description: the README without its screenshots.

Everything else is in pyproject.toml. The README's images and links are relative to the
repository, where they work; on PyPI an image link would be broken, so the screenshots are
left out and a relative link keeps its text and names the file (the sdist holds it).
"""

from __future__ import annotations

import re
from pathlib import Path

from setuptools import setup

HERE = Path(__file__).resolve().parent
IMAGE = re.compile(r"!\[[^\]]*\]\([^)]*\)")
RELATIVE_LINK = re.compile(r"\[([^\]]+)\]\((?!https?://|#)([^)]+)\)")


def long_description(readme: str) -> str:
    lines = []
    for line in readme.splitlines():
        if IMAGE.search(line):
            # A line of screenshots (an image, or a table row of them) goes; so does the
            # header of a table that only held images.
            if not IMAGE.sub("", line).strip(" |"):
                continue
            line = IMAGE.sub("", line)
        if re.fullmatch(r"\|(\s*\|)+|\|(\s*-+\s*\|)+", line.strip()):
            continue
        lines.append(RELATIVE_LINK.sub(lambda m: _link_text(m.group(1), m.group(2)), line))
    return re.sub(r"\n{3,}", "\n\n", "\n".join(lines)).strip() + "\n"


def _link_text(text: str, target: str) -> str:
    name = target.split("#", 1)[0]
    return f"`{name}`" if text.strip("`") == name else f"{text} (`{name}`)"


setup(
    long_description=long_description((HERE / "README.md").read_text(encoding="utf-8")),
    long_description_content_type="text/markdown",
)
