"""CSE 169 ``.anim`` files: read, write, summarise.

::

    animation {
      range 0 4
      numchannels 72
      channel 0 {                      (the number is optional, a label only)
        extrapolate cycle cycle
        keys 5 {
          0.0  0.1  smooth smooth      (time value tangent_in tangent_out)
          ...
        }
      }
      ...
    }

Tokens are whitespace separated, braces may be glued to words (``channel 14{``), any
line endings (LF, CRLF, ``\\r\\r\\n``, bare CR) are accepted. ``numchannels`` may be
missing or misplaced; when present it must match the number of channels read.
Tangents are ``flat | linear | smooth`` or a fixed slope (value per second); ``clamped``,
``centripetal`` and ``chordal`` (qtanimator's own rules) are accepted and written too. A
TCB (Kochanek–Bartels) side needs its key's tension, continuity and bias, which the format
cannot hold: it is written as the fixed slope it resolves to (the same curve), with an
:class:`AnimExportWarning`.

The format has no handle lengths: a channel with weighted tangents (issue 13) is written
as its :meth:`~qtanimator.core.channel.Channel.unweighted` equivalent (keys added on each
weighted span, with fixed slopes, until the curve is followed to 1e-6 of its largest
value), and :func:`format_anim` says so with an :class:`AnimExportWarning`.
"""

from __future__ import annotations

import os
import warnings
from dataclasses import replace
from pathlib import Path
from typing import Any

from qtanimator.core.channel import Channel, Extrapolation, Interpolation, Key, Tangent
from qtanimator.core.clip import AnimationClip
from qtanimator.core.keys import bounds_problem
from qtanimator.formats._tokens import Tokens, read_text, show
from qtanimator.formats.atomic import write_text_atomic
from qtanimator.formats.errors import FormatError

__all__ = ["AnimExportWarning", "AnimationClip", "load_anim", "parse_anim", "save_anim", "format_anim", "summarize"]

class AnimExportWarning(UserWarning):
    """Writing changed what a channel holds (weighted tangents became added keys)."""


_EXTRAPOLATIONS = {e.value for e in Extrapolation}
_RULES = {"flat", "linear", "smooth", "clamped", "centripetal", "chordal"}


def load_anim(path: str | os.PathLike[str]) -> AnimationClip:
    """Read an ``.anim`` file. Raises FormatError, and nothing else, on bad input."""
    return parse_anim(read_text(path), path)


def parse_anim(text: str, path: str | os.PathLike[str] | None = None) -> AnimationClip:
    tk = Tokens(text, path)
    if tk.at_end():
        raise FormatError("the file is empty; an animation file starts with 'animation {'.", path, 1)
    tk.expect("animation", "at the start of an animation file")
    tk.expect("{", "after 'animation'")
    start: float | None = None
    end: float | None = None
    declared: int | None = None
    declared_at = 0
    channels: list[Channel] = []
    while True:
        word = tk.next("'channel' or the closing '}' of the animation")
        if word == "}":
            break
        if word == "range":
            if start is not None:
                tk.error("'range' appears twice.", tk.pos - 1)
            start = tk.number("the range start")
            end = tk.number("the range end")
            if end < start:
                tk.error(f"the range ends ({end}) before it starts ({start}).", tk.pos - 1)
        elif word == "numchannels":
            if declared is not None:
                tk.error("'numchannels' appears twice.", tk.pos - 1)
            declared_at = tk.pos - 1
            declared = tk.integer("numchannels", lo=0)
        elif word == "channel":
            channels.append(_parse_channel(tk, len(channels)))
        else:
            tk.error(f"expected 'range', 'numchannels' or 'channel', found '{show(word)}'.", tk.pos - 1)
    if not tk.at_end():
        tk.error(f"unexpected '{show(tk.toks[tk.pos])}' after the end of the animation.")
    if declared is not None and declared != len(channels):
        tk.error(f"numchannels says {declared}, but the file has {len(channels)} channels.", declared_at)
    if start is None or end is None:
        times = [k.time for ch in channels for k in ch.keys]
        start, end = (min(times), max(times)) if times else (0.0, 0.0)
    return AnimationClip(channels, start, end)


def _parse_channel(tk: Tokens, index: int) -> Channel:
    label = f"channel {index}"
    word = tk.next("'{' after 'channel'")
    if word != "{":
        # Optional number label ("channel 7 {"); it must be a whole number.
        try:
            int(word)
        except ValueError:
            tk.error(f"expected '{{' or a channel number after 'channel', found '{show(word)}'.", tk.pos - 1)
        tk.expect("{", f"after '{label}'")
    pre = post = Extrapolation.CONSTANT
    keys: list[Key] | None = None
    seen_extrapolate = False
    while True:
        word = tk.next(f"'extrapolate', 'keys' or the closing '}}' of {label}")
        if word == "}":
            break
        if word == "extrapolate":
            if seen_extrapolate:
                tk.error(f"'extrapolate' appears twice in {label}.", tk.pos - 1)
            seen_extrapolate = True
            pre = _extrapolation(tk, label)
            post = _extrapolation(tk, label)
        elif word == "keys":
            if keys is not None:
                tk.error(f"'keys' appears twice in {label}.", tk.pos - 1)
            keys = _parse_keys(tk, label)
        else:
            tk.error(f"expected 'extrapolate', 'keys' or '}}' in {label}, found '{show(word)}'.", tk.pos - 1)
    problem = bounds_problem(keys or [])
    if problem is not None:  # the bounds a project holds (issue 31), so that a saved import opens again
        raise FormatError(f"{label}: {problem.replace(chr(34), chr(39))}.", tk.path, tk.line(tk.pos - 1))
    try:
        return Channel(keys or [], pre, post)
    except ValueError as exc:  # pragma: no cover - _parse_keys checks the order itself
        raise FormatError(f"{label}: {exc}.", tk.path, tk.line(tk.pos - 1)) from exc


def _extrapolation(tk: Tokens, label: str) -> Extrapolation:
    word = tk.next(f"an extrapolation mode in {label}")
    if word not in _EXTRAPOLATIONS:
        tk.error(f"unknown extrapolation '{show(word)}' in {label} "
                 "(expected constant, linear, cycle, cycle_offset or bounce).", tk.pos - 1)
    return Extrapolation(word)


def _parse_keys(tk: Tokens, label: str) -> list[Key]:
    n = tk.count(f"the key count of {label}", per_item=4)
    tk.expect("{", f"after 'keys {n}' in {label}")
    keys: list[Key] = []
    last = -float("inf")
    for i in range(n):
        if tk.peek() == "}":
            tk.error(f"{label} says it has {n} keys but lists only {i}.")
        at = tk.pos
        t = tk.number(f"the time of key {i + 1} in {label}")
        v = tk.number(f"the value of key {i + 1} in {label}")
        tin = _tangent(tk, f"the in tangent of key {i + 1} in {label}")
        tout = _tangent(tk, f"the out tangent of key {i + 1} in {label}")
        if not t > last:
            tk.error(f"key {i + 1} of {label} is at time {t}, not after the previous key ({last}); "
                     "keys must be in increasing time order.", at)
        last = t
        keys.append(Key.make(t, v, tin, tout))
    if tk.peek() != "}":
        nxt = tk.peek()
        if nxt is None:
            tk.expect("}", f"to close the keys of {label}")
        tk.error(f"{label} says it has {n} keys but lists more (found '{show(nxt or '')}' "
                 "where the closing '}' was expected).")
    tk.pos += 1
    return keys


def _tangent(tk: Tokens, what: str) -> Tangent | float:
    word = tk.next(what)
    if word in _RULES:
        return Tangent(word)
    try:
        slope = float(word)
    except ValueError:
        tk.error(f"expected flat, linear, smooth, clamped, centripetal, chordal or a number for {what}, "
                 f"found '{show(word)}'.", tk.pos - 1)
    if slope != slope or slope in (float("inf"), float("-inf")):
        tk.error(f"{what} must be a finite number, found '{show(word)}'.", tk.pos - 1)
    return slope


# ---------------------------------------------------------------------- writing
def _num(x: float) -> str:
    r = repr(float(x))
    if r.endswith(".0"):
        r = r[:-2]
    return "0" if r == "-0" else r


def _tangent_text(rule: Tangent, slope: float) -> str:
    return _num(slope) if rule is Tangent.FIXED else rule.value


def _tcb_as_fixed(ch: Channel) -> Channel:
    """The channel with every TCB side replaced by the fixed slope it resolves to."""
    s_in, s_out = ch.slopes()
    keys = []
    for i, k in enumerate(ch.keys):
        if k.in_tangent is Tangent.TCB:
            k = replace(k, in_tangent=Tangent.FIXED, in_slope=float(s_in[i]))
        if k.out_tangent is Tangent.TCB:
            k = replace(k, out_tangent=Tangent.FIXED, out_slope=float(s_out[i]))
        keys.append(k)
    return ch.with_keys(keys)


def format_anim(clip: AnimationClip) -> str:
    """The clip as ``.anim`` text (numbers written exactly: load gives the same floats).

    A channel with weighted tangents is converted to keys without weights, with an
    :class:`AnimExportWarning` per channel that says how many keys were added.
    """
    out = ["animation {", f"\trange {_num(clip.start)} {_num(clip.end)}",
           f"\tnumchannels {len(clip.channels)}"]
    for i, ch in enumerate(clip.channels):
        if any(k.interpolation is not Interpolation.CUBIC for k in ch.keys):
            raise ValueError(f"channel {i} has linear or stepped spans, which .anim files cannot store")
        if ch.is_weighted:
            ch, added, worst = ch.unweighted()
            warnings.warn(f"channel {i} has weighted tangents, which .anim files cannot hold: written with "
                          f"{added} added keys (within {worst:.1g} of the curve).", AnimExportWarning, stacklevel=2)
        if any(Tangent.TCB in (k.in_tangent, k.out_tangent) for k in ch.keys):
            ch = _tcb_as_fixed(ch)
            warnings.warn(f"channel {i} has TCB tangents, which .anim files cannot hold: written as the fixed "
                          "slopes they give (the same curve).", AnimExportWarning, stacklevel=2)
        out.append(f"\tchannel {i} {{")
        out.append(f"\t\textrapolate {ch.pre.value} {ch.post.value}")
        out.append(f"\t\tkeys {len(ch.keys)} {{")
        for k in ch.keys:
            out.append(f"\t\t\t{_num(k.time)} {_num(k.value)} {_tangent_text(k.in_tangent, k.in_slope)} "
                       f"{_tangent_text(k.out_tangent, k.out_slope)}")
        out.append("\t\t}")
        out.append("\t}")
    out.append("}")
    return "\n".join(out) + "\n"


def save_anim(clip: AnimationClip, path: str | os.PathLike[str]) -> None:
    """Write atomically: a failed save leaves the old file as it was."""
    write_text_atomic(path, format_anim(clip))


def summarize(path: str | os.PathLike[str]) -> dict[str, Any]:
    clip = load_anim(path)
    times = [k.time for ch in clip.channels for k in ch.keys]
    pairs: dict[str, int] = {}
    for ch in clip.channels:
        name = f"{ch.pre.value} {ch.post.value}"
        pairs[name] = pairs.get(name, 0) + 1
    return {
        "file": str(Path(path)),
        "kind": "CSE 169 animation",
        "range": [clip.start, clip.end],
        "channels": len(clip.channels),
        "keys": sum(len(ch.keys) for ch in clip.channels),
        "key_time_range": [min(times), max(times)] if times else None,
        "extrapolation": pairs,
    }
