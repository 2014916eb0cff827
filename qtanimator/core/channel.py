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
"""

from __future__ import annotations

import gc
import itertools
import math
import numbers
from bisect import bisect_right
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from enum import Enum, StrEnum
from typing import Any, overload

import numpy as np
import numpy.typing as npt

from qtanimator.core import bezier

FloatArray = npt.NDArray[np.float64]


class Tangent(StrEnum):
    """The rule that gives a key's in or out slope."""

    FLAT = "flat"
    LINEAR = "linear"
    SMOOTH = "smooth"
    CLAMPED = "clamped"
    FIXED = "fixed"
    #: Catmull-Rom over the keys as points ``(time, value)`` with knot spacing ``|Δp|^½``
    #: (Barry–Goldman); the slope is the curve's ``dv/dt`` at the key.
    CENTRIPETAL = "centripetal"
    #: The same with knot spacing ``|Δp|`` (chord length).
    CHORDAL = "chordal"
    #: Kochanek–Bartels: the key's tension, continuity and bias shape its in and out slopes.
    TCB = "tcb"


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

    ``in_weight`` / ``out_weight`` are handle lengths (Maya's weighted tangents, Blender's
    Bézier handles): the extent of the in / out handle along the time axis, in seconds,
    finite and positive. None (the default) is the Hermite span's handle, one third of the
    span. A cubic span from key ``a`` to key ``b`` is *weighted* when ``a.out_weight`` or
    ``b.in_weight`` is set; it is then the cubic Bézier with control points
    ``(ta, va)``, ``(ta + wa, va + wa·sa)``, ``(tb − wb, vb − wb·sb)``, ``(tb, vb)``, where
    ``sa`` / ``sb`` are the resolved out / in slopes (the tangent rules give the
    direction, the weight the length) and a missing weight counts as ``Δt/3``. When
    ``wa + wb > Δt`` evaluation scales both down in proportion so that they fill the span
    (time stays monotonic, as Blender clamps); the key keeps the lengths the user set.
    Weights on linear and stepped spans are kept but have no effect.

    ``tension`` / ``continuity`` / ``bias`` are the Kochanek–Bartels parameters (finite,
    usually in −1…1, default 0) used by a side whose rule is TCB; other rules ignore them.
    """

    time: float
    value: float
    in_tangent: Tangent = Tangent.SMOOTH
    out_tangent: Tangent = Tangent.SMOOTH
    in_slope: float = 0.0
    out_slope: float = 0.0
    interpolation: Interpolation = Interpolation.CUBIC
    broken: bool = False
    in_weight: float | None = None
    out_weight: float | None = None
    tension: float = 0.0
    continuity: float = 0.0
    bias: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.time) and math.isfinite(self.value)):
            raise ValueError(f"key time and value must be finite, got ({self.time}, {self.value})")
        if not (math.isfinite(self.in_slope) and math.isfinite(self.out_slope)):
            raise ValueError("key slopes must be finite")
        # Accept plain strings ("smooth") as well as enum members.
        object.__setattr__(self, "in_tangent", Tangent(self.in_tangent))
        object.__setattr__(self, "out_tangent", Tangent(self.out_tangent))
        object.__setattr__(self, "interpolation", Interpolation(self.interpolation))
        if self.in_weight is not None:
            object.__setattr__(self, "in_weight", _weight(self.in_weight))
        if self.out_weight is not None:
            object.__setattr__(self, "out_weight", _weight(self.out_weight))
        for name in _TCB_FIELDS:
            v = getattr(self, name)
            if v.__class__ is not float or not math.isfinite(v):
                object.__setattr__(self, name, _tcb_parameter(name, v))

    @classmethod
    def make(cls, time: float, value: float, tan_in: Tangent | str | float = Tangent.SMOOTH,
             tan_out: Tangent | str | float = Tangent.SMOOTH, **kw: Any) -> Key:
        """Build a key from ``.anim``-style tangents: a rule name or a fixed slope."""
        in_rule, in_slope = _rule_and_slope(tan_in)
        out_rule, out_slope = _rule_and_slope(tan_out)
        return cls(float(time), float(value), in_rule, out_rule, in_slope, out_slope, **kw)

    @classmethod
    def series(cls, times: npt.ArrayLike, values: npt.ArrayLike, interpolation: Interpolation,
               in_slopes: npt.ArrayLike | None = None, out_slopes: npt.ArrayLike | None = None) -> list[Key]:
        """Many keys at once, checked with numpy instead of one by one (a file's 250,000
        keys in a tenth of a second). Without slopes the tangents are linear; with them
        both sides are fixed slopes (a Hermite span, as glTF's CUBICSPLINE)."""
        t = np.asarray(times, dtype=np.float64).reshape(-1)
        v = np.asarray(values, dtype=np.float64).reshape(-1)
        fixed = in_slopes is not None or out_slopes is not None
        a = np.zeros_like(t) if in_slopes is None else np.asarray(in_slopes, dtype=np.float64).reshape(-1)
        b = np.zeros_like(t) if out_slopes is None else np.asarray(out_slopes, dtype=np.float64).reshape(-1)
        if not (len(t) == len(v) == len(a) == len(b)):
            raise ValueError("key times, values and slopes must have the same length")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
            raise ValueError("key times and values must be finite")
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
            raise ValueError("key slopes must be finite")
        rule = Tangent.FIXED if fixed else Tangent.LINEAR
        base = {"in_tangent": rule, "out_tangent": rule, "interpolation": Interpolation(interpolation),
                "broken": False, "in_weight": None, "out_weight": None, "tension": 0.0, "continuity": 0.0,
                "bias": 0.0}
        out: list[Key] = []
        new = object.__new__
        # Keys hold no cycles: the cyclic collector, which a burst of new objects triggers
        # again and again, has nothing to find here (a long clip: a third of the time).
        collecting = gc.isenabled()
        gc.disable()
        try:
            for ti, vi, ai, bi in zip(t.tolist(), v.tolist(), a.tolist(), b.tolist()):
                k = new(cls)
                d = k.__dict__
                d.update(base)
                d["time"], d["value"], d["in_slope"], d["out_slope"] = ti, vi, ai, bi
                out.append(k)
        finally:
            if collecting:
                gc.enable()
        return out

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
        if self.in_weight is not None:
            d["in_weight"] = self.in_weight
        if self.out_weight is not None:
            d["out_weight"] = self.out_weight
        # Kochanek–Bartels parameters only when set: keys without them write what they always did.
        if self.tension:
            d["tension"] = self.tension
        if self.continuity:
            d["continuity"] = self.continuity
        if self.bias:
            d["bias"] = self.bias
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Key:
        return cls.make(d["t"], d["v"], d.get("in", "smooth"), d.get("out", "smooth"),
                        interpolation=Interpolation(d.get("interp", "cubic")),
                        broken=bool(d.get("broken", False)),
                        in_weight=d.get("in_weight"), out_weight=d.get("out_weight"),
                        tension=d.get("tension", 0.0), continuity=d.get("continuity", 0.0),
                        bias=d.get("bias", 0.0))


def _weight(w: Any) -> float:
    """A handle length: a finite positive number of seconds (not a bool, not a text)."""
    if isinstance(w, (bool, str, bytes)) or not isinstance(w, numbers.Real):
        raise TypeError(f"a tangent weight must be a number of seconds, got {w!r}")
    value = float(w)
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"a tangent weight must be finite and positive, got {w!r}")
    return value


_TCB_FIELDS = ("tension", "continuity", "bias")


def _tcb_parameter(name: str, v: Any) -> float:
    """A Kochanek–Bartels parameter: a finite number (not a bool, not a text)."""
    if isinstance(v, (bool, str, bytes)) or not isinstance(v, numbers.Real):
        raise TypeError(f"a key's {name} must be a number, got {v!r}")
    value = float(v)
    if not math.isfinite(value):
        raise ValueError(f"a key's {name} must be finite, got {v!r}")
    return value


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

    Weighted spans (see :class:`Key`) are Béziers instead: ``weighted`` marks them (None
    when a channel has none, so an unweighted channel runs exactly the Hermite code), and
    ``bez`` holds the forms ``(ax, bx, cx, ay, by, cy, y0, span)`` of
    :mod:`qtanimator.core.bezier`, forward of span ``i`` at ``2·i`` and backward at
    ``2·i + 1``, with x measured as ``rel`` measures it; ``bez_l`` the same per span as
    plain floats, ``(forward, backward)``, or None for a Hermite span.
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
    weighted: npt.NDArray[np.bool_] | None = None
    bez: tuple[FloatArray, ...] = ()
    bez_l: list[tuple[tuple[float, ...], tuple[float, ...]] | None] | None = None
    # Handle extents (seconds) evaluation uses per span: out of its first key, into its last.
    handle_out: FloatArray | None = None
    handle_in: FloatArray | None = None


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
        return _weighted_spans(self.keys) is not None

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
                err = np.max(np.abs(_hermite(y[:, :1], y[:, 1:], h * s[:, :1], h * s[:, 1:], probe)
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
        if 0.0 <= w <= period and (deriv == 0 or 0.0 < w < period):
            i = bisect_right(c.rel_l, w) - 1
            if c.bez_l is not None and (bz := c.bez_l[i]) is not None:
                return _bezier(bz, w - c.rel_l[i], deriv)
            return _poly(c.coef_l[i], w - c.rel_l[i], deriv)
        if math.isnan(w):
            return math.nan
        # Outside, or a derivative at the first / last key: those belong to the extrapolation.
        before = w <= 0.0
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
        # At the first key itself, the pre side is the end of the previous period (k = −1).
        k = -1.0 if w == 0.0 else float(math.floor(w / period))
        u = min(max(w - k * period, 0.0), period)
        odd = mode is Extrapolation.BOUNCE and math.fmod(k, 2.0) != 0.0
        if odd:
            u = period - u
        i = max(bisect_right(c.rel_l, u) - 1, 0)
        if c.bez_l is not None and (bz := c.bez_l[i]) is not None:
            res = _bezier(bz, u - c.rel_l[i], deriv)
        else:
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
        if w.size and ((0.0 <= w.min() and w.max() <= period) if deriv == 0 else
                       (0.0 < w.min() and w.max() < period)):
            # Fast path: every sample lies between the first and the last key (strictly for a
            # derivative: the derivatives at the end keys are the extrapolation's).
            i = np.searchsorted(c.rel, w, side="right")
            i -= 1
            return _span_array(c, i, w - c.rel.take(i), deriv)
        with np.errstate(invalid="ignore"):
            return self._extrapolate_array(c, t, w, deriv)

    def _extrapolate_array(self, c: _Compiled, t: FloatArray, w: FloatArray, deriv: int) -> FloatArray:
        pre, post = self.pre, self.post
        period = c.period
        pre_p = pre in _PERIODIC
        post_p = post in _PERIODIC
        # Values: the keys are inside (strict boundaries). Derivatives: the first and the last
        # key belong to the pre / post extrapolation (the handout's "at and outside the end knots").
        before = w <= 0.0 if deriv else w < 0.0
        after = w >= period if deriv else w > period
        k: FloatArray | None = None
        odd: npt.NDArray[np.bool_] | None = None
        if pre_p or post_p:
            # k = floor((t - t0) / d) outside the keys, 0 inside and on non-periodic sides;
            # for a derivative at the first key itself k = −1 (the end of the period before).
            q = np.floor(w / period)
            if pre_p and post_p:
                # floor gives 0 inside, except 1 at w == d exactly (the last key itself).
                k = q
                if deriv:
                    np.copyto(k, -1.0, where=w == 0.0)
                else:
                    np.copyto(k, 0.0, where=w == period)
            elif pre_p:
                k = np.minimum(q, 0.0)
                if deriv:
                    np.copyto(k, -1.0, where=w == 0.0)
            else:
                k = np.where(after, q, 0.0)
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
        res = _span_array(c, i, u - c.rel.take(i), deriv)
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
            res = np.where(before, fill, res)
        if not post_p:
            if post is Extrapolation.LINEAR:
                fill = c.p1 + c.out1 * (t - c.t1) if deriv == 0 else (c.out1 if deriv == 1 else 0.0)
            else:
                fill = c.p1 if deriv == 0 else 0.0
            res = np.where(after, fill, res)
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
        weighted = _weighted_spans(keys) if n >= 2 else None
        extra: dict[str, Any] = {}
        if weighted is not None:
            extra = _bezier_spans(weighted, rel, values, s_in, s_out, keys)
            if weighted[-2]:
                # The sentinel continues the last (Bézier) span's derivatives at its end.
                fwd, bwd = extra["bez_l"][-2]
                b[-1] = 0.5 * bezier.evaluate_span(fwd[7], fwd, bwd, 2)
                c[-1] = bezier.evaluate_span(fwd[7], fwd, bwd, 1)
        comp = _Compiled(
            times, values, s_in, s_out, rel, a, b, c, d,
            rel.tolist(), list(zip(a.tolist(), b.tolist(), c.tolist(), d.tolist())),
            t0, t1, t1 - t0,
            float(values[0]) if n else 0.0, float(values[-1]) if n else 0.0,
            float(values[-1] - values[0]) if n else 0.0,
            float(s_in[0]) if n else 0.0, float(s_out[-1]) if n else 0.0,
            **extra,
        )
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
            for name in _TCB_FIELDS:
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


def _hermite(p0: Any, p1: Any, v0: Any, v1: Any, u: Any) -> Any:
    """The Hermite cubic with end values ``p0, p1`` and tangents ``v0, v1`` (per unit u)."""
    u2 = u * u
    u3 = u2 * u
    return (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * v0 + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * v1


def _span_array(comp: _Compiled, i: npt.NDArray[np.intp], x: FloatArray, deriv: int) -> FloatArray:
    """Evaluate span ``i`` at offset ``x``: the Hermite polynomial, then the Bézier spans
    (only where the channel has any) in place of theirs."""
    res = _poly_array(comp, i, x, deriv)
    if comp.weighted is not None:
        sel = np.flatnonzero(comp.weighted.take(i))
        if sel.size:
            res[sel] = bezier.evaluate_span_array(x.take(sel), comp.bez, i.take(sel), deriv)
    return res


def _bezier(forms: tuple[tuple[float, ...], tuple[float, ...]], x: float, deriv: int) -> float:
    return bezier.evaluate_span(x, forms[0], forms[1], deriv)


def _weighted_spans(keys: Sequence[Key]) -> npt.NDArray[np.bool_] | None:
    """Per span (plus the sentinel, never weighted): a cubic span with a weight on either
    side. None when there is none."""
    if all(k.in_weight is None and k.out_weight is None for k in keys):
        return None
    mask = np.zeros(len(keys), dtype=bool)
    for i, (ka, kb) in enumerate(zip(keys, keys[1:])):
        mask[i] = ka.interpolation is Interpolation.CUBIC and (ka.out_weight is not None or kb.in_weight is not None)
    return mask if mask.any() else None


def _bezier_spans(weighted: npt.NDArray[np.bool_], rel: FloatArray, values: FloatArray, s_in: FloatArray,
                  s_out: FloatArray, keys: Sequence[Key]) -> dict[str, Any]:
    """The Bézier data of :class:`_Compiled` for a channel with weighted spans."""
    n = len(keys)
    span = np.diff(rel)  # as the evaluation measures offsets into a span
    third = span / 3.0
    wa = np.array([third[i] if k.out_weight is None else k.out_weight for i, k in enumerate(keys[:-1])])
    wb = np.array([third[i] if k.in_weight is None else k.in_weight for i, k in enumerate(keys[1:])])
    wa, wb = bezier.effective_weights(span, wa, wb)
    # Unweighted spans keep their exact third (they are drawn and evaluated as Hermite).
    w = weighted[:-1]
    wa = np.where(w, wa, third)
    wb = np.where(w, wb, third)
    forward, backward = bezier.span_forms(span, wa, wb, np.diff(values), s_out[:-1], s_in[1:], values[:-1])
    # Interleaved (forward of span i at 2i, backward at 2i + 1), plus the sentinel's pair.
    bez = tuple(np.append(np.column_stack([f, b]).reshape(-1), [0.0, 0.0]) for f, b in zip(forward, backward))
    fwd_rows = list(zip(*(arr.tolist() for arr in forward)))
    bwd_rows = list(zip(*(arr.tolist() for arr in backward)))
    bez_l: list[tuple[tuple[float, ...], tuple[float, ...]] | None] = [
        (fwd_rows[i], bwd_rows[i]) if weighted[i] else None for i in range(n - 1)]
    bez_l.append(None)
    return {"weighted": weighted, "bez": bez, "bez_l": bez_l, "handle_out": wa, "handle_in": wb}


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
        with np.errstate(over="ignore"):  # huge secants: the product's sign is still right
            extremum = lo * hi <= 0.0
        limit = 3.0 * np.minimum(np.abs(lo), np.abs(hi))
        inner = np.clip(smooth[1:-1], -limit, limit)
        clamped[1:-1] = np.where(extremum, 0.0, inner)
    rules_in = np.array([_RULE_CODE[k.in_tangent] for k in keys], dtype=np.int8)
    rules_out = np.array([_RULE_CODE[k.out_tangent] for k in keys], dtype=np.int8)
    fixed_in = np.array([k.in_slope for k in keys])
    fixed_out = np.array([k.out_slope for k in keys])
    # Only the rules some key uses are computed and chosen from.
    used = np.flatnonzero(np.bincount(rules_in, minlength=len(_RULE_CODE))
                          + np.bincount(rules_out, minlength=len(_RULE_CODE))).tolist()
    shared: dict[int, FloatArray] = {0: np.zeros(n), 2: smooth, 3: clamped}
    for code, alpha in ((5, 0.5), (6, 1.0)):
        if code in used:
            shared[code] = _catmull_rom_slopes(times, values, alpha, smooth)
    tcb_in = tcb_out = smooth
    if 7 in used:
        tcb_in, tcb_out = _tcb_slopes(keys, times, values, secant)
    s_in = _side(rules_in, fixed_in, used, {**shared, 1: left, 7: tcb_in})
    s_out = _side(rules_out, fixed_out, used, {**shared, 1: right, 7: tcb_out})
    return s_in, s_out


#: Tangent rules as small integers, for choosing slopes with numpy.
_RULE_CODE = {Tangent.FLAT: 0, Tangent.LINEAR: 1, Tangent.SMOOTH: 2, Tangent.CLAMPED: 3, Tangent.FIXED: 4,
              Tangent.CENTRIPETAL: 5, Tangent.CHORDAL: 6, Tangent.TCB: 7}


def _side(rules: npt.NDArray[np.int8], fixed: FloatArray, used: list[int],
          slopes: dict[int, FloatArray]) -> FloatArray:
    """Each key's slope on one side from its rule: ``slopes`` holds every key's slope under
    each rule code in ``used`` (the fixed rule, 4, takes ``fixed``)."""
    codes = [code for code in used if code != 4]
    if not codes:
        return fixed
    out: FloatArray = np.select([rules == code for code in codes], [slopes[code] for code in codes], fixed)
    return out


def _catmull_rom_slopes(times: FloatArray, values: FloatArray, alpha: float, smooth: FloatArray) -> FloatArray:
    """The slope ``dv/dt`` at each key of the Catmull-Rom curve through the points
    ``p = (t, v)`` with knot spacing ``|Δp|^alpha`` (0 uniform, ½ centripetal, 1 chordal).

    The Barry–Goldman pyramid's derivative at an interior knot ``s1`` (neighbours at
    ``s0``, ``s2``) is ``(p1 − p0)/d0 − (p2 − p0)/(d0 + d1) + (p2 − p1)/d1`` with
    ``d = |Δp|^alpha``; its time and value components give the slope
    ``(w0·Δv0 + w1·Δv1) / (w0·Δt0 + w1·Δt1)`` with ``w0 = d1²``, ``w1 = d0²`` (multiplied
    through by ``d0·d1·(d0 + d1)``; scaled here by the larger one so nothing overflows).
    The denominator is positive because times increase, so the slope is always finite. At
    the first and last key the handout's mirrored virtual key makes it the one-sided secant,
    the same as ``smooth``; ``alpha = 0`` gives ``smooth`` everywhere. Where the arithmetic
    fails (values near the float limit) the key keeps its smooth slope.
    """
    out = smooth.copy()
    if len(times) < 3:
        return out
    dt = np.diff(times)
    dv = np.diff(values)
    length = np.hypot(dt, dv)
    h0, h1 = length[:-1], length[1:]
    big = np.maximum(h0, h1)
    with np.errstate(all="ignore"):
        w0 = (h1 / big) ** (2.0 * alpha)
        w1 = (h0 / big) ** (2.0 * alpha)
        slope = (w0 * dv[:-1] + w1 * dv[1:]) / (w0 * dt[:-1] + w1 * dt[1:])
    out[1:-1] = np.where(np.isfinite(slope), slope, smooth[1:-1])
    return out


def _tcb_slopes(keys: Sequence[Key], times: FloatArray, values: FloatArray,
                secant: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Kochanek–Bartels in and out slopes of every key (its tension T, continuity C, bias B).

    With ``Δ0 = v[i] − v[i−1]`` and ``Δ1 = v[i+1] − v[i]``, the tangents per unit parameter
    (Kochanek & Bartels 1984) are
    ``out = (1−T)/2·((1+B)(1+C)·Δ0 + (1−B)(1−C)·Δ1)`` and
    ``in = (1−T)/2·((1+B)(1−C)·Δ0 + (1−B)(1+C)·Δ1)``; their step-size adjustment for
    keys unevenly spaced in time makes both slopes ``tangent · 2 / (t[i+1] − t[i−1])``.
    So T = C = B = 0 is ``smooth``. At the first and last key, with one neighbour, both
    slopes are ``(1−T)`` times the one-sided secant (C and B have no second span to weigh).
    """
    n = len(keys)
    tension = np.array([k.tension for k in keys])
    cont = np.array([k.continuity for k in keys])
    bias = np.array([k.bias for k in keys])
    scale = 1.0 - tension
    s_in = np.empty(n)
    s_out = np.empty(n)
    s_in[0] = s_out[0] = scale[0] * secant[0]
    s_in[-1] = s_out[-1] = scale[-1] * secant[-1]
    if n > 2:
        d0 = values[1:-1] - values[:-2]
        d1 = values[2:] - values[1:-1]
        t, c, b = scale[1:-1], cont[1:-1], bias[1:-1]
        per_second = 2.0 / (times[2:] - times[:-2])
        s_out[1:-1] = 0.5 * t * ((1 + b) * (1 + c) * d0 + (1 - b) * (1 - c) * d1) * per_second
        s_in[1:-1] = 0.5 * t * ((1 + b) * (1 - c) * d0 + (1 - b) * (1 + c) * d1) * per_second
    return s_in, s_out


def catmull_rom(points: Iterable[tuple[float, float]]) -> Channel:
    """The CMU reference spline: smooth tangents with constant extrapolation."""
    return Channel([Key(t, v) for t, v in points])
