"""A pass over an SVG before svgelements reads it: refuse what would take too long or too much.

svgelements is a good reader of honest drawings, but its work grows with what a hostile file
can multiply, and several of its regular expressions backtrack:

- every ``<use>`` is expanded in place, recursively (a few KB of ``<use>`` of ``<use>`` make
  billions of elements; a ``<use>`` that refers to its own group never ends);
- every element copies the attributes of the groups around it and parses their transforms,
  colours and lengths again, and the ``<style>`` rules that match it;
- ``rgb(…)`` colours with long digit runs, unclosed ``(`` in transforms, ``url(`` in
  ``clip-path``, ``;`` inside a ``font``, digit runs in ``points`` and unclosed rules or
  comments in ``<style>`` make its regular expressions take quadratic or worse time.

:func:`check_budget` reads the XML once with expat (linear; entity expansion stays under
expat's own amplification limit and external entities are never loaded), builds a small
tree, and measures the document *as svgelements will expand it*: elements, nesting depth,
``<use>`` copies and how deeply they chain, path points, inherited transforms, attributes and
style text. Anything beyond a limit of :mod:`qtanimator.formats.limits` is refused with a
FormatError naming the limit and, where there is one, the line. Values on which svgelements'
regular expressions would backtrack are refused too. Malformed XML is left to the caller,
which reports it as it always has.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from xml.parsers import expat

from qtanimator.formats import limits
from qtanimator.formats.errors import FormatError

_SVG_NS = "http://www.w3.org/2000/svg"
_XLINK_HREF = "{http://www.w3.org/1999/xlink}href"
_HREFS = ("href", _XLINK_HREF)
#: Above this size the pass uses ElementTree's parser, which has no line numbers but feeds expat
#: the whole text at once: pyexpat feeds 1 MB at a time, and expat 2.5 scans a token that spans
#: many feeds again on every feed (quadratic in the size of a huge attribute).
_LINES_UP_TO = 16 << 20

#: svgelements' number (``PATTERN_FLOAT``): counting these counts what its path lexer reads.
_FLOAT = re.compile(r"[-+]?[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?")
#: A ``points`` list svgelements reads in linear time: numbers of bounded length, separated by
#: commas, white space or the next number's sign or decimal point (possessive: no backtracking).
_POINTS = re.compile(
    r"[\s,]*+(?:[-+]?+(?:[0-9]{1,40}+(?:\.[0-9]{0,40}+)?+|\.[0-9]{1,40}+)(?:[eE][-+]?+[0-9]{1,5}+)?+"
    r"(?:[\s,]++|(?=[-+.])|\Z))*+")
#: A transform whose parentheses all close and do not nest.
_BALANCED = re.compile(r"[^()]*+(?:\([^()]*+\)[^()]*+)*+")
#: A whole-number part of 5 digits or more: svgelements' ``rgb(…)`` expression can split such a
#: run between ``[0-9]*`` and ``[0-9]+`` in as many ways as it has digits, for each of its four
#: numbers, so a failing match costs (digits)⁴ steps (a fraction after '.' splits one way only).
_LONG_DIGITS = re.compile(r"(?<![0-9.])[0-9]{5}")
_CSS_COMMENT = re.compile(r"\/\*[\s\S]*?\*\/|\/\/.*$", re.MULTILINE)  # svgelements' REGEX_CSS_COMMENT
_CSS_RULE = re.compile(r"([^{]+)\s*\{\s*([^}]+)\s*\}")  # svgelements' REGEX_CSS_STYLE
#: Rules one after the other, as svgelements' expression can read them without backtracking.
_CSS_TILES = re.compile(r"(?:[^{}]++\{[^}]*+\}\s*+)*+")
_CSS_EMPTY_RULE = re.compile(r"\{\s*+\}")
_COLOUR_KEYS = frozenset({"fill", "stroke", "color", "stop-color", "flood-color", "lighting-color"})
#: Attributes that svgelements reads once (or never) and does not parse per element.
_LONG_OK = frozenset({"id", "class", "style"})


def _too_much(what: str, found: int, limit: int, name: str, path: str | os.PathLike[str] | None,
              line: int | None = None) -> FormatError:
    err = limits.exceeded(f"{what} ({found:,})", f"{limit:,} ({name})", path)
    return FormatError(err.message, path, line)


class _Tree:
    """The elements of the document in document order: tag, attributes, line, children."""

    def __init__(self) -> None:
        self.tags: list[str] = []
        self.attrs: list[dict[str, str]] = []
        self.lines: list[int | None] = []
        self.children: list[list[int]] = []
        self.style_text: dict[int, list[str]] = {}
        # per element, what it costs itself (the aggregation multiplies by copies)
        self.own_points: list[int] = []
        self.own_transforms: list[int] = []
        self.own_keys: list[int] = []
        self.own_style: list[int] = []


class _Reader:
    """Builds the :class:`_Tree` with expat, refusing what is too big as soon as it is seen.

    Also an ElementTree parser target (``start``, ``end``, ``data``, ``close``).
    """

    def __init__(self, path: str | os.PathLike[str] | None, lines: bool) -> None:
        self.path = path
        self.tree = _Tree()
        self.stack: list[int] = []
        self.path_bytes = 0
        self.style_bytes = 0
        #: The first invalid value. It is raised after the whole file parsed, so that XML that is
        #: not well-formed further on is reported as such (sizes are refused at once).
        self.invalid: FormatError | None = None
        self.parser: expat.XMLParserType | None = None
        if lines:
            self.parser = expat.ParserCreate(namespace_separator="}")
            self.parser.buffer_text = True
            self.parser.StartElementHandler = self.start
            self.parser.EndElementHandler = self.end
            self.parser.CharacterDataHandler = self.data

    def parse(self, data: bytes) -> None:
        """Read ``data``; expat.ExpatError or ET.ParseError for XML that is not well-formed."""
        if self.parser is not None:
            self.parser.Parse(data, True)
        else:
            et = ET.XMLParser(target=self)
            et.feed(data)
            et.close()

    @property
    def line(self) -> int | None:
        return self.parser.CurrentLineNumber if self.parser is not None else None

    def close(self) -> None:
        pass

    # ------------------------------------------------------------------ handlers
    def start(self, name: str, attrs: dict[str, str]) -> None:
        t = self.tree
        index = len(t.tags)
        line = self.line
        if index >= limits.MAX_SVG_ELEMENTS:
            raise _too_much("the number of elements", index + 1, limits.MAX_SVG_ELEMENTS, "MAX_SVG_ELEMENTS",
                            self.path, line)
        if len(self.stack) >= limits.MAX_SVG_DEPTH:
            raise _too_much("the nesting depth of elements", len(self.stack) + 1, limits.MAX_SVG_DEPTH,
                            "MAX_SVG_DEPTH", self.path, line)
        tag = _svg_tag(name)
        clean: dict[str, str] = {}
        for key, value in attrs.items():
            clean["{" + key if "}" in key and key[0] != "{" else key] = value
        t.tags.append(tag)
        t.attrs.append(clean)
        t.lines.append(line)
        t.children.append([])
        if self.stack:
            t.children[self.stack[-1]].append(index)
        self.stack.append(index)
        if tag == "style":
            t.style_text[index] = []
        self._measure(index, tag, clean, line)

    def end(self, name: str) -> None:
        self.stack.pop()

    def data(self, data: str) -> None:
        # svgelements reads a <style>'s text before its first child (ElementTree's ``text``)
        if self.stack:
            top = self.stack[-1]
            parts = self.tree.style_text.get(top)
            if parts is not None and not self.tree.children[top]:
                parts.append(data)
                self.style_bytes += len(data)
                if self.style_bytes > limits.MAX_ATTRIBUTE_BYTES:
                    raise _too_much("the text of the <style> elements, in characters", self.style_bytes,
                                    limits.MAX_ATTRIBUTE_BYTES, "MAX_ATTRIBUTE_BYTES", self.path, self.line)

    # -------------------------------------------------------------- per element
    def _measure(self, index: int, tag: str, attrs: dict[str, str], line: int | None) -> None:
        points = 0
        keys = len(attrs)
        style_bytes = 0
        transform = attrs.get("transform", "")
        for key, value in attrs.items():
            if key in ("d", "points"):
                self.path_bytes += len(value)
                if self.path_bytes > limits.MAX_PATH_DATA_BYTES:
                    raise _too_much("the path data (d and points) of the drawing, in characters", self.path_bytes,
                                    limits.MAX_PATH_DATA_BYTES, "MAX_PATH_DATA_BYTES", self.path, line)
                if key == "points" and _POINTS.fullmatch(value) is None and self.invalid is None:
                    self.invalid = FormatError(f"the points of <{_local(tag)}> are not a list of numbers "
                                               "separated by commas or spaces.", self.path, line)
                points += _FLOAT.subn("", value)[1]
                continue
            if key in _HREFS:
                continue  # a reference or an image's data: never parsed per element
            if key in _LONG_OK or key.startswith("{"):
                cap, cap_name = limits.MAX_ATTRIBUTE_BYTES, "MAX_ATTRIBUTE_BYTES"
            else:
                cap, cap_name = limits.MAX_SVG_VALUE_BYTES, "MAX_SVG_VALUE_BYTES"
            if len(value) > cap:
                raise _too_much(f"the {_show(key)} attribute of <{_local(tag)}>, in characters", len(value), cap,
                                cap_name, self.path, line)
            if key == "style":
                style_bytes += len(value)
                for prop, val in _declarations(value):
                    keys += 1
                    self._check_value(prop, val, f"the style of <{_local(tag)}>", line)
                    if prop == "transform":
                        transform = val
            elif key in ("class", "id"):
                style_bytes += len(value)  # every copy of the element looks up '#id' and '.class' rules
            elif cap == limits.MAX_SVG_VALUE_BYTES:
                self._check_value(key, value, f"<{_local(tag)}>", line)
        t = self.tree
        t.own_points.append((points + 1) // 2)
        t.own_transforms.append(transform.count("(") + (1 if tag in ("use", "svg") else 0))
        t.own_keys.append(keys)
        t.own_style.append(style_bytes)

    def _check_value(self, key: str, value: str, where: str, line: int | None) -> None:
        try:
            check_value(key, value, where, self.path, line)
        except FormatError as exc:
            if self.invalid is None:
                self.invalid = exc


def check_value(key: str, value: str, where: str, path: str | os.PathLike[str] | None,
                line: int | None) -> None:
    """FormatError for a presentation value svgelements would parse in more than linear time."""
    if len(value) > limits.MAX_SVG_VALUE_BYTES and key not in _LONG_OK:
        raise _too_much(f"the {_show(key)} value of {where}, in characters", len(value),
                        limits.MAX_SVG_VALUE_BYTES, "MAX_SVG_VALUE_BYTES", path, line)
    if key == "transform":
        if _BALANCED.fullmatch(value) is None:
            raise FormatError(f"the transform of {where} is not valid: its parentheses do not pair up.", path, line)
    elif key in _COLOUR_KEYS:
        # only rgb(…) / hsl(…) reach the backtracking expressions (they match from the start)
        if value.startswith(("rgb", "hsl")) and _LONG_DIGITS.search(value) is not None:
            raise FormatError(f"the {key} colour of {where} is not valid: a number in it is too long.", path, line)
    elif key == "clip-path":
        if value.count("url(") > 1:
            raise FormatError(f"the clip-path of {where} is not valid: it names more than one url(…).", path, line)
    elif key == "font":
        semicolon = value.find(";")
        if semicolon != -1 and semicolon != len(value) - 1:
            raise FormatError(f"the font of {where} is not valid: it contains ';'.", path, line)


def _declarations(style: str) -> list[tuple[str, str]]:
    """``key: value`` pairs of a style text, split as svgelements splits them (linear)."""
    out = []
    for equate in style.split(";"):
        item = equate.split(":")
        if len(item) == 2:
            out.append((item[0].strip(), item[1].strip()))
    return out


def _svg_tag(name: str) -> str:
    """The tag as svgelements sees it: the SVG namespace removed, any other one kept."""
    if "}" not in name:
        return name
    if name[0] != "{":
        name = "{" + name
    return name[28:] if name.startswith("{" + _SVG_NS) else name  # as svgelements: tag[28:]


def _local(tag: str) -> str:
    """A tag for a message: without its namespace."""
    return tag.rsplit("}", 1)[-1]


def _show(key: str) -> str:
    return key if len(key) <= 40 else key[:39] + "…"


# ---------------------------------------------------------------------- <style> rules
def _css_rules(tree: _Tree, path: str | os.PathLike[str] | None) -> dict[str, str]:
    """Selector → declarations of every <style> element, as svgelements collects them.

    The text is checked first so that svgelements' own expressions stay linear on it: comments
    left open, text after the last rule, a rule without a selector, or a long selector before
    an empty rule ``{}`` would make them backtrack over the whole text.
    """
    styles: dict[str, str] = {}
    for index, parts in tree.style_text.items():
        line = tree.lines[index]
        text = "".join(parts)
        last_close = text.rfind("*/")
        if text.count("/*", last_close + 2 if last_close >= 0 else 0) > 1:
            raise FormatError("a <style> element has comments that are not closed ('/*' without '*/').", path, line)
        text = _CSS_COMMENT.sub("", text).strip()
        if not text:
            continue
        if _CSS_TILES.fullmatch(text) is None:
            raise FormatError("a <style> element is not a list of complete rules 'selector { … }'.", path, line)
        for m in _CSS_EMPTY_RULE.finditer(text):
            before = text.rfind("}", 0, m.start()) + 1
            if m.start() - before > 256:
                raise FormatError("a <style> element has an empty rule '{}' after a very long selector.", path, line)
        for key, value in _CSS_RULE.findall(text):
            value = value.strip()
            for prop, val in _declarations(value):
                check_value(prop, val, "a <style> rule", path, line)
            for selector in key.strip().split(","):
                sel = selector.strip()
                if sel not in styles:
                    styles[sel] = value
                else:
                    styles[sel] = styles[sel] + ("" if styles[sel].endswith(";") else ";") + value
    return styles


def _css_bytes(tree: _Tree, index: int, styles: dict[str, str]) -> int:
    """Characters of <style> rules svgelements applies to one element (all <style>s counted)."""
    tag = tree.tags[index]
    attrs = tree.attrs[index]
    total = len(styles.get("*", "")) + len(styles.get(tag, ""))
    if "id" in attrs:
        total += len(styles.get("#" + attrs["id"], ""))
    if "class" in attrs:
        for cls in attrs["class"].split(" "):
            total += len(styles.get("." + cls, "")) + len(styles.get(f"{tag}.{cls}", ""))
    return total


# ------------------------------------------------------------------------- the check
def check_budget(data: bytes, path: str | os.PathLike[str] | None = None) -> None:
    """FormatError if svgelements would need more than the limits to read ``data``.

    Returns quietly for XML that expat cannot parse: the caller reports it with its usual
    message (line and column of the error).
    """
    reader = _Reader(path, lines=len(data) <= _LINES_UP_TO)
    try:
        reader.parse(data)
    except (expat.ExpatError, ET.ParseError):
        return
    except RecursionError:  # pragma: no cover - expat is iterative; a handler never recurses
        raise FormatError("the elements are nested too deeply.", path) from None
    if reader.invalid is not None:
        raise reader.invalid
    tree = reader.tree
    if not tree.tags:
        return
    styles = _css_rules(tree, path) if tree.style_text else {}
    if styles:
        for i in range(len(tree.tags)):
            tree.own_style[i] += _css_bytes(tree, i, styles)
    _expand(tree, path)


def _targets(tree: _Tree) -> list[int]:
    """For each element, the element its ``<use>`` copies (-1 if none), as svgelements finds it."""
    ids: dict[str, int] = {}
    for i, a in enumerate(tree.attrs):
        if "id" in a:
            ids[a["id"]] = i  # the last element with an id wins, as in svgelements
    out = [-1] * len(tree.tags)
    for i, tag in enumerate(tree.tags):
        if tag != "use":
            continue
        a = tree.attrs[i]
        url = a.get("href", a.get(_XLINK_HREF))
        if url is not None:
            out[i] = ids.get(url[1:], -1)
    return out


def _expand(tree: _Tree, path: str | os.PathLike[str] | None) -> None:
    """Aggregate every element's cost over the document as svgelements expands it.

    Bottom-up with memoisation over the tree plus the ``<use>`` edges (a graph without
    cycles once they are refused), so a ``<use>`` bomb is measured in time linear in the
    file, not in its expansion. Inherited costs (transforms, attributes, path data that
    descendants inherit) are ``copies × own cost + children's``, which is exact for any
    context the element is copied into.
    """
    n = len(tree.tags)
    target = _targets(tree)
    count = [0] * n
    uses = [0] * n
    use_depth = [0] * n
    depth = [0] * n
    points = [0] * n
    transforms = [0] * n
    keys = [0] * n
    style = [0] * n
    state = bytearray(n)  # 0 new, 1 on the stack, 2 done
    cursor = [0] * n
    stack = [0]
    state[0] = 1
    while stack:
        v = stack[-1]
        kids = tree.children[v]
        k = cursor[v]
        if k <= len(kids):
            cursor[v] = k + 1
            w = kids[k] if k < len(kids) else target[v]
            if w < 0:
                continue
            if state[w] == 1:
                raise _cycle(tree, stack, w, target, path)
            if state[w] == 0:
                state[w] = 1
                stack.append(w)
            continue
        succ = kids if target[v] < 0 else [*kids, target[v]]
        c = 1 + sum(count[s] for s in succ)
        count[v] = c
        uses[v] = sum(uses[s] for s in succ) + (1 if target[v] >= 0 else 0)
        use_depth[v] = max([use_depth[s] for s in kids] + ([1 + use_depth[target[v]]] if target[v] >= 0 else [0]))
        depth[v] = 1 + max((depth[s] for s in succ), default=0)
        points[v] = c * tree.own_points[v] + sum(points[s] for s in succ)
        transforms[v] = c * tree.own_transforms[v] + sum(transforms[s] for s in succ)
        keys[v] = c * tree.own_keys[v] + sum(keys[s] for s in succ)
        style[v] = tree.own_style[v] + sum(style[s] for s in succ)
        _check_aggregate(tree, v, path, c, uses[v], use_depth[v], depth[v], points[v], transforms[v], keys[v],
                         style[v])
        state[v] = 2
        stack.pop()


def _check_aggregate(tree: _Tree, v: int, path: str | os.PathLike[str] | None, count: int, uses: int,
                     use_depth: int, depth: int, points: int, transforms: int, keys: int, style: int) -> None:
    line = tree.lines[v]
    if use_depth > limits.MAX_SVG_USE_DEPTH:
        raise _too_much("the chain of <use> elements that copy each other", use_depth, limits.MAX_SVG_USE_DEPTH,
                        "MAX_SVG_USE_DEPTH", path, line)
    if uses > limits.MAX_SVG_USE_EXPANSIONS:
        raise _too_much("the number of copies that <use> elements make", uses, limits.MAX_SVG_USE_EXPANSIONS,
                        "MAX_SVG_USE_EXPANSIONS", path, line)
    if count > limits.MAX_SVG_ELEMENTS:
        raise _too_much("the number of elements, counting <use> copies", count, limits.MAX_SVG_ELEMENTS,
                        "MAX_SVG_ELEMENTS", path, line)
    if depth > limits.MAX_SVG_DEPTH:
        raise _too_much("the nesting depth of elements, counting <use> copies", depth, limits.MAX_SVG_DEPTH,
                        "MAX_SVG_DEPTH", path, line)
    if points > limits.MAX_PATH_POINTS:
        raise _too_much("the number of path points, counting <use> copies", points, limits.MAX_PATH_POINTS,
                        "MAX_PATH_POINTS", path, line)
    if transforms > limits.MAX_SVG_INHERITED_TRANSFORMS:
        raise _too_much("the number of transforms to evaluate (each element repeats those of the groups "
                        "around it)", transforms, limits.MAX_SVG_INHERITED_TRANSFORMS,
                        "MAX_SVG_INHERITED_TRANSFORMS", path, line)
    if keys > limits.MAX_SVG_INHERITED_ATTRIBUTES:
        raise _too_much("the number of attributes to copy (each element repeats those of the groups around it)",
                        keys, limits.MAX_SVG_INHERITED_ATTRIBUTES, "MAX_SVG_INHERITED_ATTRIBUTES", path, line)
    if style > limits.MAX_SVG_STYLE_BYTES:
        raise _too_much("the style text to apply, in characters", style, limits.MAX_SVG_STYLE_BYTES,
                        "MAX_SVG_STYLE_BYTES", path, line)


def _cycle(tree: _Tree, stack: list[int], w: int, target: list[int],
           path: str | os.PathLike[str] | None) -> FormatError:
    """The error for a ``<use>`` that (through others) copies an element containing itself."""
    on_cycle = stack[stack.index(w):]
    use = next((v for v in reversed(on_cycle) if target[v] >= 0), on_cycle[-1])
    ref = tree.attrs[use].get("href", tree.attrs[use].get(_XLINK_HREF, ""))
    return FormatError(f"the <use> refers to '{_show(ref)}', which contains that <use>: its copies would never "
                       "end.", path, tree.lines[use])
