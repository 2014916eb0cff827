"""The CSE 169 tokenizer (issue #19): linear on big and hostile text, with the same tokens and lines.

Big files are read in a child process limited to 1 GiB of address space; its timeout is a
limit that turns a hang into a failure (generous, for a loaded CI machine), not a speed
assertion. The measured times are in the issue's report.
"""

from __future__ import annotations

import json
import random
import re
import resource
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from qtanimator.formats import _tokens, limits
from qtanimator.formats._tokens import Tokens
from qtanimator.formats.anim import parse_anim
from qtanimator.formats.errors import FormatError

ROOT = Path(__file__).resolve().parents[2]
MEMORY_LIMIT = 1 << 30
TIMEOUT_S = 30

CHILD = r"""
import json, sys
from qtanimator.formats.errors import FormatError
from qtanimator.formats._tokens import Tokens, read_text
from qtanimator.formats.anim import load_anim
path = sys.argv[1]
try:
    tokens = len(Tokens(read_text(path), path))
    clip = load_anim(path)
except FormatError as exc:
    print(json.dumps({"error": str(exc), "line": exc.line}))
else:
    print(json.dumps({"tokens": tokens, "channels": len(clip.channels)}))
"""


def _limit_memory() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))


def read_limited(path: Path) -> dict[str, object]:
    done = subprocess.run([sys.executable, "-c", CHILD, str(path)], capture_output=True, text=True,
                          timeout=TIMEOUT_S, preexec_fn=_limit_memory, cwd=ROOT)
    assert done.returncode == 0, f"something other than FormatError escaped:\n{done.stderr[-3000:]}"
    result: dict[str, object] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def big_anim(megabytes: float, keys_per_channel: int = 200) -> tuple[str, int]:
    """A valid .anim of about ``megabytes`` MB and its channel count."""
    rng = random.Random(1)
    channels: list[str] = []
    size = 0
    while size < megabytes * 1e6:
        keys = "\n".join(f"\t\t\t{k * 0.05:.4f} {rng.uniform(-3, 3):.6f} smooth smooth"
                         for k in range(keys_per_channel))
        ch = (f"\tchannel {len(channels)} {{\n\t\textrapolate cycle constant\n\t\tkeys {keys_per_channel} {{\n{keys}"
              "\n\t\t}\n\t}")
        channels.append(ch)
        size += len(ch)
    text = f"animation {{\n\trange 0 10\n\tnumchannels {len(channels)}\n" + "\n".join(channels) + "\n}\n"
    return text, len(channels)


def test_ten_megabyte_anim_is_read(tmp_path: Path) -> None:
    text, channels = big_anim(10)
    path = tmp_path / "big.anim"
    path.write_text(text)
    result = read_limited(path)
    assert result == {"tokens": len(text.replace("{", " { ").replace("}", " } ").split()), "channels": channels}


def test_error_at_the_end_of_a_big_file_has_its_line(tmp_path: Path) -> None:
    text, _ = big_anim(3)
    lines = text.count("\n")
    text = text[:-2] + "\n\toops\n}\n"  # an unknown word on the second to last line
    with pytest.raises(FormatError, match="found 'oops'") as info:
        parse_anim(text, "big.anim")
    assert info.value.line == lines + 1


@pytest.mark.parametrize("name,text,message", [
    ("one line of numbers", "animation { " + "1 " * 5_000_000 + "}", "expected 'range', 'numchannels' or 'channel'"),
    ("braces only", "{" * 5_000_000, "expected 'animation'"),
    ("comments only", "# x\n" * 2_000_000 + "// y\r" * 1_000_000, "empty"),
    ("bare CR line breaks", "\r" * 5_000_000 + "animation { oops }", "found 'oops'"),
    ("more tokens than the limit", "1\n" * (limits.MAX_TOKENS + 1), "MAX_TOKENS"),
])
def test_hostile_text_is_refused_within_budget(tmp_path: Path, name: str, text: str, message: str) -> None:
    path = tmp_path / "hostile.anim"
    path.write_text(text, newline="")
    result = read_limited(path)
    assert "error" in result and message in str(result["error"]), result
    if name == "bare CR line breaks":
        assert result["line"] == 5_000_001


def test_token_limit_names_the_limit_and_line(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(limits, "MAX_TOKENS", 1000)
    monkeypatch.setattr(_tokens, "_BLOCK", 64)
    with pytest.raises(FormatError, match=r"MAX_TOKENS") as info:
        Tokens("a b\n" * 600, "x.anim")
    assert info.value.line == 501  # token 1001 is the first word of line 501


# ------------------------------------------------- the same tokens and lines as before
_OLD_BREAK = re.compile(r"\r\n|\r|\n")


def reference(text: str, braces: bool = True, comments: bool = True) -> tuple[list[str], list[int], int]:
    """The tokenizer before issue #19, line by line: the oracle for tokens and line numbers."""
    if text.startswith("\ufeff"):
        text = text[1:]
    toks: list[str] = []
    lines: list[int] = []
    split = _OLD_BREAK.split(text)
    for number, line in enumerate(split, start=1):
        if comments and ("#" in line or "//" in line):
            m = re.search(r"#|//", line)
            if m is not None:
                line = line[: m.start()]
        if braces:
            line = re.sub(r"([{}])", r" \1 ", line)
        parts = line.split()
        toks.extend(parts)
        lines.extend([number] * len(parts))
    return toks, lines, max(1, len(split))


PIECES = ["a", "12", "-3.5e4", " ", "\t", "\n", "\r", "\r\n", "{", "}", "#", "//", "/", "# note\n", "\ufeff",
          "\x0b", "\x0c", "\x1c", "\x85", "\u2028", "\xa0", "\u3000", "é", "keys"]


@settings(derandomize=True, max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.sampled_from(PIECES), max_size=80), st.booleans(), st.booleans(), st.sampled_from([3, 16, 1 << 18]))
def test_tokens_and_lines_as_before(pieces: list[str], braces: bool, comments: bool, block: int) -> None:
    text = "".join(pieces)
    old = _tokens._BLOCK
    _tokens._BLOCK = block  # small blocks: tokens and lines across block boundaries
    try:
        tk = Tokens(text, "x", braces=braces, comments=comments)
    finally:
        _tokens._BLOCK = old
    toks, lines, last_line = reference(text, braces, comments)
    assert tk.toks == toks
    assert [tk.line(i) for i in range(len(toks))] == lines == tk.lines
    assert tk.last_line == last_line
    assert tk.line(len(toks)) == (lines[-1] if lines else 1)  # past the end: the last token's line


class _NoMemory(str):
    """Text whose blocks cannot be allocated, as when a huge file meets a memory limit."""

    def __getitem__(self, key: object) -> str:
        raise MemoryError


def test_running_out_of_memory_is_a_format_error() -> None:
    with pytest.raises(FormatError, match="memory ran out") as info:
        Tokens(_NoMemory("1 2 3"), "x.anim")
    assert info.value.path == "x.anim"


def test_a_reader_asking_the_line_of_every_row_stays_linear(tmp_path: Path) -> None:
    """The .skin reader asks for a line number per weight row; 60,000 rows must read in a
    limited child process well within its timeout (line lookups once cost a scan of the
    token's block each: quadratic, minutes for this file)."""
    n = 60_000
    rows = "\n".join(f"\t{i % 7 * 0.1:.1f} {i % 5 * 0.1:.1f} 0.0" for i in range(n))
    weights = "\n".join("\t2 0 0.5 1 0.5" for _ in range(n))
    text = (f"positions {n} {{\n{rows}\n}}\nnormals {n} {{\n{rows}\n}}\nskinweights {n} {{\n{weights}\n}}\n"
            f"triangles 1 {{\n\t0 1 2\n}}\nbindings 2 {{\n matrix {{\n 1 0 0\n 0 1 0\n 0 0 1\n 0 0 0\n }}\n"
            f" matrix {{\n 1 0 0\n 0 1 0\n 0 0 1\n 0 1 0\n }}\n}}\n")
    path = tmp_path / "big.skin"
    path.write_text(text)
    script = (f"from qtanimator.formats.skin import load_skin\n"
              f"s = load_skin({str(path)!r})\nprint('VERTICES', len(s.positions))\n")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60,
                            preexec_fn=_limit_memory)
    assert f"VERTICES {n}" in result.stdout, result.stderr[-2000:]
