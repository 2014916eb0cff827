"""Animation channels: keys with tangent rules, Hermite spans and extrapolation.

The semantics are fixed by ARCHITECTURE section 4 and notes/cse169-formats.md section 8:

* a key is ``(time, value, in, out)``; each side has a rule ``flat | linear | smooth |
  clamped`` or a fixed slope (value per second);
* the span after key ``i`` is cubic Hermite with ``v0 = Δt·out[i]``, ``v1 = Δt·in[i+1]``,
  or linear, or constant (stepped);
* before the first key and after the last one the pre / post extrapolation applies, with
  strict boundaries and the floor convention at exact period multiples.

A :class:`Channel` is an immutable value. Editing operations return a new channel, which
keeps undo exact (a command stores the old and the new object) and lets caches key on
object identity. Evaluation is vectorised: one ``searchsorted`` and a gather of per-span
polynomial coefficients, no Python loop per sample.
"""

from __future__ import annotations

import itertools
import math
from bisect import bisect_right
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from enum import Enum, StrEnum
from typing import Any, overload

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]


class Tangent(StrEnum):
    """The rule that gives a key's in or out slope."""

    FLAT = "flat"
    LINEAR = "linear"
    SMOOTH = "smooth"
    CLAMPED = "clamped"
    FIXED = "fixed"


class Extrapolation(StrEnum):
    """What a channel does before its first key (pre) or after its last key (post)."""

    CONSTANT = "constant"
    LINEAR = "linear"
    CYCLE = "cycle"
    CYCLE_OFFSET = "cycle_offset"
    BOUNCE = "bounce"

    @property
    def periodic(self) -> bool:
        """True for the modes that repeat the keys (cycle, cycle_offset, bounce)."""
        return self in _PERIODIC


class Interpolation(StrEnum):
    """The shape of the span that starts at a key."""

    CUBIC = "cubic"
    LINEAR = "linear"
    CONSTANT = "constant"


@dataclass(frozen=True)
class Key:
    """One key. ``in_slope`` / ``out_slope`` are used only when that side is FIXED.

    ``broken`` records whether the curve editor moves the in and out handles apart; it
    does not change evaluation.
    """

    time: float
    value: float
    in_tangent: Tangent = Tangent.SMOOTH
    out_tangent: Tangent = Tangent.SMOOTH
    in_slope: float = 0.0
    out_slope: float = 0.0
    interpolation: Interpolation = Interpolation.CUBIC
    broken: bool = False

    def __post_init__(self) -> None:
        if not (math.isfinite(self.time) and math.isfinite(self.value)):
            raise ValueError(f"key time and value must be finite, got ({self.time}, {self.value})")
        if not (math.isfinite(self.in_slope) and math.isfinite(self.out_slope)):
            raise ValueError("key slopes must be finite")
        # Accept plain strings ("smooth") as well as enum members.
        object.__setattr__(self, "in_tangent", Tangent(self.in_tangent))
        object.__setattr__(self, "out_tangent", Tangent(self.out_tangent))
        object.__setattr__(self, "interpolation", Interpolation(self.interpolation))

    @classmethod
    def make(cls, time: float, value: float, tan_in: Tangent | str | float = Tangent.SMOOTH,
             tan_out: Tangent | str | float = Tangent.SMOOTH, **kw: Any) -> Key:
        """Build a key from ``.anim``-style tangents: a rule name or a fixed slope."""
        in_rule, in_slope = _rule_and_slope(tan_in)
        out_rule, out_slope = _rule_and_slope(tan_out)
        return cls(float(time), float(value), in_rule, out_rule, in_slope, out_slope, **kw)

    def moved(self, time: float, value: float) -> Key:
        """The same key (rules, slopes, span shape) at another time and value."""
        return replace(self, time=float(time), value=float(value))

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"t": self.time, "v": self.value}
        d["in"] = self.in_slope if self.in_tangent is Tangent.FIXED else self.in_tangent.value
        d["out"] = self.out_slope if self.out_tangent is Tangent.FIXED else self.out_tangent.value
        if self.interpolation is not Interpolation.CUBIC:
            d["interp"] = self.interpolation.value
        if self.broken:
            d["broken"] = True
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Key:
        return cls.make(d["t"], d["v"], d.get("in", "smooth"), d.get("out", "smooth"),
                        interpolation=Interpolation(d.get("interp", "cubic")),
                        broken=bool(d.get("broken", False)))


def _rule_and_slope(tan: Tangent | str | float) -> tuple[Tangent, float]:
    if isinstance(tan, Tangent):
        return tan, 0.0
    if isinstance(tan, str):
        return Tangent(tan), 0.0
    slope = float(tan)
    if not math.isfinite(slope):
        raise ValueError("a fixed slope must be finite")
    return Tangent.FIXED, slope


_PERIODIC = (Extrapolation.CYCLE, Extrapolation.CYCLE_OFFSET, Extrapolation.BOUNCE)

#: Large arrays are evaluated in blocks of this many samples, so that the dozen or so
#: numpy passes per block stay in the CPU cache.
_BLOCK = 65536


@dataclass(frozen=True, eq=False)
class _Compiled:
    """Everything evaluation needs, computed once per channel.

    The polynomial of span ``i`` is ``((a x + b) x + c) x + d`` with ``x = t − times[i]``
    in seconds (the Hermite form of notes §8.2 with ``u = x/Δ`` folded into the
    coefficients). Index ``n − 1`` is a sentinel "span" that starts at the last key: its
    value is exactly the last key's value and its first and second derivatives are those
    at the end of the last real span, so ``t == t_last`` needs no special case and a
    stepped last span ends on its key.
    """

    times: FloatArray
    values: FloatArray
    slope_in: FloatArray
    slope_out: FloatArray
    rel: FloatArray  # times − t0, computed exactly like ``t − t0`` for a sample
    a: FloatArray
    b: FloatArray
    c: FloatArray
    d: FloatArray
    # Plain-float copies for the scalar path (bisect and Python arithmetic, same rounding).
    rel_l: list[float]
    coef_l: list[tuple[float, float, float, float]]
    t0: float
    t1: float
    period: float
    p0: float
    p1: float
    rise: float  # p_last − p0, the cycle_offset step
    in0: float   # the first key's in slope (linear pre-extrapolation)
    out1: float  # the last key's out slope (linear post-extrapolation)


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
    _compiled: list[_Compiled] = field(default_factory=list, repr=False, compare=False, hash=False)

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
        if flat.size <= _BLOCK:
            out = self._evaluate_array(flat, derivative)
        else:
            out = np.empty_like(flat)
            for s in range(0, flat.size, _BLOCK):
                out[s:s + _BLOCK] = self._evaluate_array(flat[s:s + _BLOCK], derivative)
        return out.reshape(tt.shape)

    def __call__(self, t: Any, derivative: int = 0) -> Any:
        return self.evaluate(t, derivative)

    # The scalar and the array paths do the same floating-point operations in the same
    # order, so they agree to the last bit (a test checks this).
    def _evaluate_scalar(self, t: float, deriv: int) -> float:
        n = len(self.keys)
        if n == 0:
            return 0.0
        c = self._compile()
        if n == 1:
            return math.nan if math.isnan(t) else (c.p0 if deriv == 0 else 0.0)
        w = t - c.t0
        period = c.period
        if 0.0 <= w <= period:
            i = bisect_right(c.rel_l, w) - 1
            return _poly(c.coef_l[i], w - c.rel_l[i], deriv)
        if math.isnan(w):
            return math.nan
        before = w < 0.0
        mode = self.pre if before else self.post
        if mode is Extrapolation.CONSTANT:
            return (c.p0 if before else c.p1) if deriv == 0 else 0.0
        if mode is Extrapolation.LINEAR:
            slope = c.in0 if before else c.out1
            if deriv == 0:
                return c.p0 + c.in0 * w if before else c.p1 + c.out1 * (t - c.t1)
            return slope if deriv == 1 else 0.0
        if not math.isfinite(w):
            return math.nan  # an infinite time has no place in a period
        k = float(math.floor(w / period))
        u = min(max(w - k * period, 0.0), period)
        odd = mode is Extrapolation.BOUNCE and math.fmod(k, 2.0) != 0.0
        if odd:
            u = period - u
        i = max(bisect_right(c.rel_l, u) - 1, 0)
        res = _poly(c.coef_l[i], u - c.rel_l[i], deriv)
        if odd and deriv == 1:
            res = -res
        if mode is Extrapolation.CYCLE_OFFSET and deriv == 0:
            res += k * c.rise
        return res

    def _evaluate_array(self, t: FloatArray, deriv: int) -> FloatArray:
        n = len(self.keys)
        if n == 0:
            return np.zeros_like(t)
        c = self._compile()
        if n == 1:
            res = np.full_like(t, c.p0 if deriv == 0 else 0.0)
            res[np.isnan(t)] = np.nan
            return res
        period = c.period
        w = t - c.t0
        if w.size and 0.0 <= w.min() and w.max() <= period:
            # Fast path: every sample lies between the first and the last key.
            i = np.searchsorted(c.rel, w, side="right")
            i -= 1
            return _poly_array(c, i, w - c.rel.take(i), deriv)
        with np.errstate(invalid="ignore"):
            return self._extrapolate_array(c, t, w, deriv)

    def _extrapolate_array(self, c: _Compiled, t: FloatArray, w: FloatArray, deriv: int) -> FloatArray:
        pre, post = self.pre, self.post
        period = c.period
        pre_p = pre in _PERIODIC
        post_p = post in _PERIODIC
        k: FloatArray | None = None
        odd: npt.NDArray[np.bool_] | None = None
        if pre_p or post_p:
            # k = floor((t - t0) / d) outside the keys, 0 inside and on non-periodic sides.
            q = np.floor(w / period)
            if pre_p and post_p:
                # floor gives 0 inside, except 1 at w == d exactly (the last key itself).
                k = q
                np.copyto(k, 0.0, where=w == period)
            elif pre_p:
                k = np.minimum(q, 0.0)
            else:
                k = np.where(w > period, q, 0.0)
            u = k * period
            np.subtract(w, u, out=u)
            if pre is Extrapolation.BOUNCE or post is Extrapolation.BOUNCE:
                odd = np.fmod(k, 2.0) != 0.0
                if pre is not Extrapolation.BOUNCE:
                    odd &= k > 0.0
                elif post is not Extrapolation.BOUNCE:
                    odd &= k < 0.0
        else:
            u = w.copy()
        np.clip(u, 0.0, period, out=u)
        if odd is not None:
            u = np.where(odd, period - u, u)
        # u >= 0 = rel[0], so i >= 0. NaN samples (and infinite ones in a periodic mode)
        # sort after every key, land in the sentinel and stay NaN all the way through.
        i = np.searchsorted(c.rel, u, side="right")
        i -= 1
        res = _poly_array(c, i, u - c.rel.take(i), deriv)
        if odd is not None and deriv == 1:
            np.negative(res, out=res, where=odd)
        if k is not None and deriv == 0:
            if pre is Extrapolation.CYCLE_OFFSET and post is Extrapolation.CYCLE_OFFSET:
                res += k * c.rise
            elif pre is Extrapolation.CYCLE_OFFSET:
                res += np.minimum(k, 0.0) * c.rise
            elif post is Extrapolation.CYCLE_OFFSET:
                res += np.maximum(k, 0.0) * c.rise
        if not pre_p:
            fill: Any
            if pre is Extrapolation.LINEAR:
                fill = c.p0 + c.in0 * w if deriv == 0 else (c.in0 if deriv == 1 else 0.0)
            else:
                fill = c.p0 if deriv == 0 else 0.0
            res = np.where(w < 0.0, fill, res)
        if not post_p:
            if post is Extrapolation.LINEAR:
                fill = c.p1 + c.out1 * (t - c.t1) if deriv == 0 else (c.out1 if deriv == 1 else 0.0)
            else:
                fill = c.p1 if deriv == 0 else 0.0
            res = np.where(w > period, fill, res)
        return res

    def _compile(self) -> _Compiled:
        if self._compiled:
            return self._compiled[0]
        keys = self.keys
        n = len(keys)
        times = np.array([k.time for k in keys], dtype=np.float64)
        values = np.array([k.value for k in keys], dtype=np.float64)
        s_in, s_out = _resolve_slopes(keys, times, values)
        a = np.zeros(n)
        b = np.zeros(n)
        c = np.zeros(n)
        d = values.copy()
        if n >= 2:
            dt = np.diff(times)
            p0, p1 = values[:-1], values[1:]
            interp = [k.interpolation for k in keys[:-1]]
            cubic = np.array([m is Interpolation.CUBIC for m in interp])
            linear = np.array([m is Interpolation.LINEAR for m in interp])
            # Hermite coefficients over u in [0, 1] (notes §8.2), then scaled to seconds.
            v0 = dt * s_out[:-1]
            v1 = dt * s_in[1:]
            A = np.where(cubic, 2 * p0 - 2 * p1 + v0 + v1, 0.0)
            B = np.where(cubic, -3 * p0 + 3 * p1 - 2 * v0 - v1, 0.0)
            C = np.where(cubic, v0, np.where(linear, p1 - p0, 0.0))
            inv = 1.0 / dt
            a[:-1] = A * inv ** 3
            b[:-1] = B * inv ** 2
            c[:-1] = C * inv
            # The sentinel continues the derivatives of the last span at its end.
            h = dt[-1]
            b[-1] = 3.0 * a[-2] * h + b[-2]
            c[-1] = (3.0 * a[-2] * h + 2.0 * b[-2]) * h + c[-2]
        t0 = float(times[0]) if n else 0.0
        t1 = float(times[-1]) if n else 0.0
        rel = times - t0
        comp = _Compiled(
            times, values, s_in, s_out, rel, a, b, c, d,
            rel.tolist(), list(zip(a.tolist(), b.tolist(), c.tolist(), d.tolist())),
            t0, t1, t1 - t0,
            float(values[0]) if n else 0.0, float(values[-1]) if n else 0.0,
            float(values[-1] - values[0]) if n else 0.0,
            float(s_in[0]) if n else 0.0, float(s_out[-1]) if n else 0.0,
        )
        self._compiled.append(comp)
        return comp

    # ------------------------------------------------------------- persistence
    def to_dict(self, columns: bool = False) -> dict[str, Any]:
        """Plain JSON data: ``pre``, ``post`` and the keys.

        By default the keys are a list of objects ``{"t", "v", "in", "out"[, "interp"]
        [, "broken"]}`` (project format 1; :meth:`Document.state` compares this form).
        With ``columns`` they are columns (project format 2): ``times`` and ``values``
        arrays, and ``in`` / ``out`` / ``interp`` / ``broken`` each written once when every
        key shares it (an ``in`` rule name or fixed slope) and as one entry per key
        otherwise; ``interp`` is left out when every span is cubic and ``broken`` when no
        key is broken, as in the key form.
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
        columns = {name: d.get(name, default) for name, default in
                   (("in", "smooth"), ("out", "smooth"), ("interp", "cubic"), ("broken", False))}
        for name, column in columns.items():
            if isinstance(column, list) and len(column) != n:
                raise ValueError(f"\"{name}\" has {len(column)} entries for {n} keys")
        ins, outs, interps, brokens = columns.values()
        if not all(isinstance(b, bool) for b in (brokens if isinstance(brokens, list) else [brokens])):
            raise TypeError("\"broken\" must be true or false")
        if not isinstance(brokens, list):
            brokens = itertools.repeat(brokens, n)
        if not any(isinstance(c, list) for c in (ins, outs, interps)):
            # Every key shares its rules: resolve them once (a long channel loads faster).
            in_rule, in_slope = _rule_and_slope(ins)
            out_rule, out_slope = _rule_and_slope(outs)
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


def _poly(coef: tuple[float, float, float, float], x: float, deriv: int) -> float:
    a, b, c, d = coef
    if deriv == 0:
        return ((a * x + b) * x + c) * x + d
    if deriv == 1:
        return (3.0 * a * x + 2.0 * b) * x + c
    return 6.0 * a * x + 2.0 * b


def _poly_array(comp: _Compiled, i: npt.NDArray[np.intp], x: FloatArray, deriv: int) -> FloatArray:
    """Evaluate span ``i`` at offset ``x`` (in place on temporaries, same order as _poly)."""
    a = comp.a.take(i)
    if deriv == 0:
        a *= x
        a += comp.b.take(i)
        a *= x
        a += comp.c.take(i)
        a *= x
        a += comp.d.take(i)
        return a
    if deriv == 1:
        a *= 3.0
        a *= x
        a += 2.0 * comp.b.take(i)
        a *= x
        a += comp.c.take(i)
        return a
    a *= 6.0
    a *= x
    a += 2.0 * comp.b.take(i)
    return a


def _resolve_slopes(keys: Sequence[Key], times: FloatArray,
                    values: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Turn each key's in / out rule into a slope (notes/cse169-formats.md 8.1)."""
    n = len(keys)
    s_in = np.zeros(n)
    s_out = np.zeros(n)
    if n < 2:
        return s_in, s_out
    secant = np.diff(values) / np.diff(times)  # slope of span i (keys i, i+1)
    # One-sided slopes: towards the previous key for "in", the next key for "out";
    # at the ends both sides use the only neighbouring span.
    left = np.concatenate([[secant[0]], secant])    # span ending at key i
    right = np.concatenate([secant, [secant[-1]]])  # span starting at key i
    smooth = right.copy()
    if n > 2:
        smooth[1:-1] = (values[2:] - values[:-2]) / (times[2:] - times[:-2])
    smooth[0] = secant[0]
    smooth[-1] = secant[-1]
    clamped = smooth.copy()
    if n > 2:
        lo, hi = secant[:-1], secant[1:]
        extremum = lo * hi <= 0.0
        limit = 3.0 * np.minimum(np.abs(lo), np.abs(hi))
        inner = np.clip(smooth[1:-1], -limit, limit)
        clamped[1:-1] = np.where(extremum, 0.0, inner)
    for i, k in enumerate(keys):
        s_in[i] = _side(k.in_tangent, k.in_slope, left[i], smooth[i], clamped[i])
        s_out[i] = _side(k.out_tangent, k.out_slope, right[i], smooth[i], clamped[i])
    return s_in, s_out


def _side(rule: Tangent, fixed: float, linear: float, smooth: float, clamped: float) -> float:
    if rule is Tangent.FLAT:
        return 0.0
    if rule is Tangent.LINEAR:
        return float(linear)
    if rule is Tangent.SMOOTH:
        return float(smooth)
    if rule is Tangent.CLAMPED:
        return float(clamped)
    return float(fixed)


def catmull_rom(points: Iterable[tuple[float, float]]) -> Channel:
    """The CMU reference spline: smooth tangents with constant extrapolation."""
    return Channel([Key(t, v) for t, v in points])
