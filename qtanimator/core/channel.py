"""Animation channels: keys with tangent rules, Hermite spans and extrapolation.

The semantics are fixed by ARCHITECTURE section 4 and notes/cse169-formats.md section 8:

* a key is ``(time, value, in, out)``; each side has a rule ``flat | linear | smooth |
  clamped | centripetal | chordal | tcb`` or a fixed slope (value per second);
* the span after key ``i`` is cubic Hermite with ``v0 = Δt·out[i]``, ``v1 = Δt·in[i+1]``,
  or linear, or constant (stepped);
* before the first key and after the last one the pre / post extrapolation applies, with
  strict boundaries for values and the floor convention at exact period multiples; the
  derivatives *at* the first and last key are the extrapolation's (the CMU handout: at and
  outside the end knots a constant spline's derivatives are 0);
* a key may carry handle lengths (weighted tangents, issue 13): a cubic span with a weight
  on either side is a cubic Bézier in time and value, evaluated exactly by solving for its
  parameter (:mod:`qtanimator.core.bezier`); spans without weights are Hermite as above.

A :class:`Channel` is an immutable value. Editing operations return a new channel, which
keeps undo exact (a command stores the old and the new object) and lets caches key on
object identity. Evaluation is vectorised: one ``searchsorted`` and a gather of per-span
polynomial coefficients, no Python loop per sample.

Layout: the keys, tangent rules and extrapolation modes live in :mod:`qtanimator.core.keys`
(re-exported here), the compiled evaluation in :mod:`qtanimator.core.channel_eval`.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from enum import Enum
from typing import Any, overload

import numpy as np
import numpy.typing as npt

from qtanimator.core.channel_eval import (
    BLOCK,
    Compiled,
    compile_keys,
    evaluate_array,
    evaluate_scalar,
    hermite,
    weighted_spans,
)
from qtanimator.core.keys import TCB_FIELDS, rule_and_slope
from qtanimator.core.keys import Extrapolation as Extrapolation
from qtanimator.core.keys import Interpolation as Interpolation
from qtanimator.core.keys import Key as Key
from qtanimator.core.keys import Tangent as Tangent

FloatArray = npt.NDArray[np.float64]

__all__ = ["Channel", "Extrapolation", "FloatArray", "Interpolation", "Key", "Tangent", "catmull_rom"]


@dataclass(frozen=True, eq=True)
class Channel:
    """An animation channel: sorted keys plus pre / post extrapolation.

    >>> ch = Channel([Key(0, 0), Key(1, 2)])
    >>> ch.evaluate(0.5)
    1.0
    """

    keys: tuple[Key, ...] = ()
    pre: Extrapolation = Extrapolation.CONSTANT
    post: Extrapolation = Extrapolation.CONSTANT
    _compiled: list[Compiled] = field(default_factory=list, repr=False, compare=False, hash=False)
    _derived: dict[str, Any] = field(default_factory=dict, repr=False, compare=False, hash=False)

    def __init__(self, keys: Iterable[Key] = (), pre: Extrapolation | str = Extrapolation.CONSTANT,
                 post: Extrapolation | str = Extrapolation.CONSTANT) -> None:
        ordered = tuple(sorted(keys, key=lambda k: k.time))
        for a, b in zip(ordered, ordered[1:]):
            if not b.time > a.time:
                raise ValueError(f"two keys share the time {a.time}")
        object.__setattr__(self, "keys", ordered)
        object.__setattr__(self, "pre", Extrapolation(pre))
        object.__setattr__(self, "post", Extrapolation(post))
        object.__setattr__(self, "_compiled", [])
        object.__setattr__(self, "_derived", {})

    def __hash__(self) -> int:
        return hash((self.keys, self.pre, self.post))

    # ------------------------------------------------------------------ editing
    def __len__(self) -> int:
        return len(self.keys)

    @property
    def times(self) -> FloatArray:
        return self._compile().times

    @property
    def values(self) -> FloatArray:
        return self._compile().values

    @property
    def linear_spans(self) -> npt.NDArray[np.bool_]:
        """Per span (key i to key i + 1) whether it is linear; computed once per channel."""
        found = self._derived.get("linear_spans")
        if found is None:
            found = np.array([k.interpolation is Interpolation.LINEAR for k in self.keys[:-1]], dtype=bool)
            self._derived["linear_spans"] = found
        result: npt.NDArray[np.bool_] = found
        return result

    def with_keys(self, keys: Iterable[Key]) -> Channel:
        return Channel(keys, self.pre, self.post)

    def with_extrapolation(self, pre: Extrapolation | str | None = None,
                           post: Extrapolation | str | None = None) -> Channel:
        return Channel(self.keys, self.pre if pre is None else pre, self.post if post is None else post)

    def key_index(self, time: float, tolerance: float = 1e-9) -> int | None:
        """Index of the key within ``tolerance`` of ``time``, or None."""
        if not self.keys:
            return None
        times = self.times
        i = int(np.argmin(np.abs(times - time)))
        return i if abs(times[i] - time) <= tolerance else None

    def set_key(self, key: Key, tolerance: float = 1e-9) -> Channel:
        """Insert ``key``, replacing a key at the same time (within ``tolerance``).

        When a key is replaced, the existing key's tangent rules and span shape are kept
        and only its value changes, as an animator expects from "set key".
        """
        i = self.key_index(key.time, tolerance)
        keys = list(self.keys)
        if i is None:
            keys.append(key)
        else:
            keys[i] = keys[i].moved(keys[i].time, key.value)
        return self.with_keys(keys)

    def remove_keys(self, indices: Iterable[int]) -> Channel:
        drop = set(indices)
        return self.with_keys(k for i, k in enumerate(self.keys) if i not in drop)

    def replace_keys(self, changes: dict[int, Key]) -> Channel:
        """Replace keys by index; raises ValueError if two keys would share a time."""
        return self.with_keys(changes.get(i, k) for i, k in enumerate(self.keys))

    # -------------------------------------------------------------- evaluation
    def slopes(self) -> tuple[FloatArray, FloatArray]:
        """The resolved in and out slopes of every key (value per second)."""
        c = self._compile()
        return c.slope_in, c.slope_out

    @property
    def is_weighted(self) -> bool:
        """True when some span is weighted (a cubic Bézier with handle lengths, see :class:`Key`)."""
        if self._compiled:
            return self._compiled[0].weighted is not None
        return weighted_spans(self.keys) is not None

    def span_handles(self) -> tuple[npt.NDArray[np.bool_], FloatArray, FloatArray]:
        """Per span (``len(keys) − 1`` entries): whether it is weighted, and the extents
        along time (seconds) of its out handle (at its first key) and its in handle (at its
        last key) as evaluation uses them: the key's weight or ``Δt/3``, clamped to the span.
        The Bézier of span ``i`` has control points ``(t[i], v[i])``,
        ``(t[i] + h_out[i], v[i] + h_out[i]·out[i])``, ``(t[i+1] − h_in[i], v[i+1] −
        h_in[i]·in[i+1])``, ``(t[i+1], v[i+1])`` with the slopes of :meth:`slopes`."""
        c = self._compile()
        n = len(self.keys)
        if n < 2:
            return np.zeros(0, dtype=bool), np.zeros(0), np.zeros(0)
        if c.weighted is None or c.handle_out is None or c.handle_in is None:
            third = np.diff(c.rel) / 3.0
            return np.zeros(n - 1, dtype=bool), third, third.copy()
        return c.weighted[:-1].copy(), c.handle_out.copy(), c.handle_in.copy()

    def unweighted(self, tolerance: float | None = None, max_keys: int = 4096) -> tuple[Channel, int, float]:
        """An equivalent channel without weights, for formats that cannot hold them.

        Each weighted span is cut in halves, and the halves in halves where needed, by keys
        on the curve whose fixed slopes are its derivative there, until every Hermite piece
        stays within ``tolerance`` of the Bézier (default ``1e-6 × max(1, largest
        |value|)``; checked against half of it at 15 points per piece, a margin for the
        points between) or the span has ``max_keys`` new keys. The keys at the ends of a
        weighted span get fixed slopes (their resolved ones), since new neighbours would
        change a rule; every other key, the extrapolation and the unweighted spans stay as
        they are. Returns the channel, how many keys were added and the largest deviation
        found. A channel without weighted spans is returned as it is.
        """
        c = self._compile()
        if c.weighted is None:
            return self, 0, 0.0
        tol = tolerance if tolerance is not None else 1e-6 * max(1.0, float(np.max(np.abs(c.values))))
        keys = [replace(k, in_weight=None, out_weight=None) for k in self.keys]
        worst = 0.0
        probe = np.arange(1, 16) / 16.0
        for i in np.flatnonzero(c.weighted):
            ta, tb = float(c.times[i]), float(c.times[i + 1])
            for j in (i, i + 1):
                keys[j] = replace(keys[j], in_tangent=Tangent.FIXED, out_tangent=Tangent.FIXED,
                                  in_slope=float(c.slope_in[j]), out_slope=float(c.slope_out[j]))

            def on_span(t: FloatArray, deriv: int, i: int = int(i), ta: float = ta, tb: float = tb) -> FloatArray:
                # This span's own curve, also at its ends (the channel gives the next span's
                # derivatives at tb, and the extrapolation's at the first and last key).
                res: FloatArray = self.evaluate(t, deriv)
                start = c.values[i] if deriv == 0 else c.slope_out[i]
                end = c.values[i + 1] if deriv == 0 else c.slope_in[i + 1]
                return np.where(t == tb, end, np.where(t == ta, start, res))

            cuts: list[float] = []
            pieces = np.array([[ta, tb]])
            while pieces.size:
                lo, hi = pieces[:, :1], pieces[:, 1:]
                h = hi - lo
                check = lo + h * probe
                ends = np.concatenate([lo, hi], axis=1)
                y, s = on_span(ends, 0), on_span(ends, 1)
                err = np.max(np.abs(hermite(y[:, :1], y[:, 1:], h * s[:, :1], h * s[:, 1:], probe)
                                    - on_span(check, 0)), axis=1)
                mid = (0.5 * (lo + hi))[:, 0]
                split = (err > 0.5 * tol) & (lo[:, 0] < mid) & (mid < hi[:, 0])
                if len(cuts) + int(split.sum()) > max_keys:
                    split[:] = False
                worst = max(worst, float(np.max(err[~split], initial=0.0)))
                cuts += mid[split].tolist()
                pieces = np.concatenate([np.column_stack([lo[split, 0], mid[split]]),
                                         np.column_stack([mid[split], hi[split, 0]])])
            if cuts:
                t = np.array(sorted(cuts))
                values, slopes = on_span(t, 0), on_span(t, 1)
                keys += [Key(float(x), float(v), Tangent.FIXED, Tangent.FIXED, float(d), float(d))
                         for x, v, d in zip(t, values, slopes)]
        return Channel(keys, self.pre, self.post), len(keys) - len(self.keys), worst

    @overload
    def evaluate(self, t: float, derivative: int = 0) -> float: ...
    @overload
    def evaluate(self, t: npt.ArrayLike, derivative: int = 0) -> Any: ...

    def evaluate(self, t: Any, derivative: int = 0) -> Any:
        """Value (``derivative=0``), slope (1) or curvature (2) at ``t`` seconds.

        Returns a float for a scalar time and a float64 array of the same shape for an
        array of times. At an interior key the derivatives are those of the span that
        starts there (the out side).
        """
        if derivative not in (0, 1, 2):
            raise ValueError("derivative must be 0, 1 or 2")
        if np.ndim(t) == 0:
            return self._evaluate_scalar(float(t), derivative)
        tt = np.asarray(t, dtype=np.float64)
        flat = tt.reshape(-1)
        if flat.size <= BLOCK:
            out = self._evaluate_array(flat, derivative)
        else:
            out = np.empty_like(flat)
            for s in range(0, flat.size, BLOCK):
                out[s:s + BLOCK] = self._evaluate_array(flat[s:s + BLOCK], derivative)
        return out.reshape(tt.shape)

    def __call__(self, t: Any, derivative: int = 0) -> Any:
        return self.evaluate(t, derivative)

    def _evaluate_scalar(self, t: float, deriv: int) -> float:
        n = len(self.keys)
        if n == 0:
            return 0.0
        return evaluate_scalar(self._compile(), n, self.pre, self.post, t, deriv)

    def _evaluate_array(self, t: FloatArray, deriv: int) -> FloatArray:
        n = len(self.keys)
        if n == 0:
            return np.zeros_like(t)
        return evaluate_array(self._compile(), n, self.pre, self.post, t, deriv)

    def _compile(self) -> Compiled:
        if self._compiled:
            return self._compiled[0]
        comp = compile_keys(self.keys)
        self._compiled.append(comp)
        return comp

    # ------------------------------------------------------------- persistence
    def to_dict(self, columns: bool = False) -> dict[str, Any]:
        """Plain JSON data: ``pre``, ``post`` and the keys.

        By default the keys are a list of objects ``{"t", "v", "in", "out"[, "interp"]
        [, "broken"][, "in_weight"][, "out_weight"]}`` (project format 1;
        :meth:`Document.state` compares this form). With ``columns`` they are columns
        (project format 2): ``times`` and ``values`` arrays, and ``in`` / ``out`` /
        ``interp`` / ``broken`` / ``in_weight`` / ``out_weight`` each written once when
        every key shares it (an ``in`` rule name or fixed slope) and as one entry per key
        otherwise; ``interp`` is left out when every span is cubic, ``broken`` when no key
        is broken and a weight column when no key has that weight (a key without one is
        ``null`` in a per-key column), as in the key form. So a channel without weights
        writes exactly what it wrote before weights existed. The Kochanek–Bartels columns
        ``tension`` / ``continuity`` / ``bias`` are written likewise only when some key has
        a non-zero one (0 for the others in a per-key column).
        """
        d: dict[str, Any] = {"pre": self.pre.value, "post": self.post.value}
        if not columns:
            d["keys"] = [k.to_dict() for k in self.keys]
            return d
        keys = self.keys
        if keys:
            d["in"] = _rule_column([k.in_tangent for k in keys], [k.in_slope for k in keys])
            d["out"] = _rule_column([k.out_tangent for k in keys], [k.out_slope for k in keys])
            interp = _shared([k.interpolation for k in keys])
            if interp is not Interpolation.CUBIC:
                d["interp"] = interp._value_ if isinstance(interp, Interpolation) else [m._value_ for m in interp]
            broken = _shared([k.broken for k in keys])
            if broken is not False:
                d["broken"] = broken
            for side in ("in_weight", "out_weight"):
                weights = [getattr(k, side) for k in keys]
                if any(w is not None for w in weights):
                    d[side] = _shared(weights)
            for name in TCB_FIELDS:
                params = [getattr(k, name) for k in keys]
                if any(params):
                    d[name] = _shared(params)
        # Plain floats (a key made in code may hold an int): what loads back saves the same.
        d["times"] = [float(k.time) for k in keys]
        d["values"] = [float(k.value) for k in keys]
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Channel:
        """Read either form written by :meth:`to_dict` (ValueError / TypeError / KeyError if
        it is malformed)."""
        pre, post = d.get("pre", "constant"), d.get("post", "constant")
        if "times" not in d and "values" not in d:
            return cls([Key.from_dict(k) for k in d.get("keys", [])], pre, post)
        if "keys" in d:
            raise ValueError("a channel has either \"keys\" or \"times\" and \"values\", not both")
        times, values = d["times"], d["values"]
        if not isinstance(times, list) or not isinstance(values, list):
            raise TypeError("\"times\" and \"values\" must be lists")
        n = len(times)
        if len(values) != n:
            raise ValueError(f"{n} times but {len(values)} values")
        columns: dict[str, Any] = {name: d.get(name, default) for name, default in
                   (("in", "smooth"), ("out", "smooth"), ("interp", "cubic"), ("broken", False),
                    ("in_weight", None), ("out_weight", None), ("tension", None),
                    ("continuity", None), ("bias", None))}
        for name, column in columns.items():
            if isinstance(column, list) and len(column) != n:
                raise ValueError(f"\"{name}\" has {len(column)} entries for {n} keys")
        ins, outs, interps, brokens, in_ws, out_ws, tens, conts, biases = columns.values()
        if not all(isinstance(b, bool) for b in (brokens if isinstance(brokens, list) else [brokens])):
            raise TypeError("\"broken\" must be true or false")
        if not isinstance(brokens, list):
            brokens = itertools.repeat(brokens, n)
        if in_ws is not None or out_ws is not None or any(c is not None for c in (tens, conts, biases)):
            # Weights and Kochanek–Bartels parameters are rare: such a channel takes the per-key path.
            tens, conts, biases = (0.0 if c is None else c for c in (tens, conts, biases))
            ins, outs, interps, in_ws, out_ws, tens, conts, biases = (
                c if isinstance(c, list) else itertools.repeat(c, n)
                for c in (ins, outs, interps, in_ws, out_ws, tens, conts, biases))
            return cls([Key.make(t, v, i, o, interpolation=Interpolation(m), broken=b, in_weight=iw, out_weight=ow,
                                 tension=tt, continuity=cc, bias=bb)
                        for t, v, i, o, m, b, iw, ow, tt, cc, bb in zip(times, values, ins, outs, interps, brokens,
                                                                       in_ws, out_ws, tens, conts, biases)],
                       pre, post)
        if not any(isinstance(c, list) for c in (ins, outs, interps)):
            # Every key shares its rules: resolve them once (a long channel loads faster).
            in_rule, in_slope = rule_and_slope(ins)
            out_rule, out_slope = rule_and_slope(outs)
            interp = Interpolation(interps)
            return cls([Key(float(t), float(v), in_rule, out_rule, in_slope, out_slope, interp, b)
                        for t, v, b in zip(times, values, brokens)], pre, post)
        ins, outs, interps = (c if isinstance(c, list) else itertools.repeat(c, n) for c in (ins, outs, interps))
        return cls([Key.make(t, v, i, o, interpolation=Interpolation(m), broken=b)
                    for t, v, i, o, m, b in zip(times, values, ins, outs, interps, brokens)], pre, post)


_FIXED = Tangent.FIXED


def _shared(items: list[Any]) -> Any:
    """The one value every item has, or ``items`` itself when they differ. Items of one
    value must also have one type and one ``repr`` (``1`` is not ``1.0``, ``-0.0`` is not
    ``0.0``), so a shared value writes every item exactly."""
    first = items[0]
    # list.count compares by identity first: one rule (an enum member) or one bool is fast.
    if items.count(first) != len(items):
        return items
    if isinstance(first, (Enum, bool)) or all(item is first for item in items):
        return first
    if len({type(item) for item in items}) != 1 or len({repr(item) for item in items}) != 1:
        return items
    return first


def _rule_column(rules: list[Tangent], slopes: list[float]) -> Any:
    """One side's tangents in the column form: a rule name or a fixed slope, shared by
    every key or one per key. ``_value_`` is a member's plain string (``.value`` is a slow
    property)."""
    rule = _shared(rules)
    if rule is _FIXED:
        return _shared([float(s) for s in slopes])
    if isinstance(rule, Tangent):
        return rule._value_
    return [float(s) if r is _FIXED else r._value_ for r, s in zip(rules, slopes)]



def catmull_rom(points: Iterable[tuple[float, float]]) -> Channel:
    """The CMU reference spline: smooth tangents with constant extrapolation."""
    return Channel([Key(t, v) for t, v in points])
