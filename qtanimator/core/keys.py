"""Keys of an animation channel: tangent rules, span shapes, extrapolation modes and the
slopes the rules give (ARCHITECTURE section 4, notes/cse169-formats.md section 8).

* a key is ``(time, value, in, out)``; each side has a rule ``flat | linear | smooth |
  clamped | centripetal | chordal | tcb`` or a fixed slope (value per second);
* :func:`resolve_slopes` turns every key's rules into slopes (notes 8.1), vectorised;
* a key may carry handle lengths (weighted tangents, issue 13) and Kochanek–Bartels
  parameters, see :class:`Key`.

:mod:`qtanimator.core.channel` builds channels of these keys (and re-exports them).
"""

from __future__ import annotations

import gc
import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass, replace
from enum import StrEnum
from typing import Any

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]

#: Two key times closer than this (seconds) are the same time: editing treats them as one
#: key, and a project or glTF file whose keys of one channel are closer is refused.
KEY_TIME_TOLERANCE = 1e-6
#: The largest key time (seconds, either sign) a file may hold: 11.6 days of animation.
#: Beyond it, spans and frame numbers lose the precision the views need.
MAX_KEY_TIME = 1e6
#: The largest key value, fixed slope (value per second), tangent weight (seconds) or
#: Kochanek–Bartels parameter a project may hold (either sign). Sums and products of a few
#: such numbers stay finite, so no view computes an infinite or NaN range from them.
MAX_KEY_VALUE = 1e9

__all__ = ["KEY_TIME_TOLERANCE", "MAX_KEY_TIME", "MAX_KEY_VALUE", "PERIODIC", "TCB_FIELDS",
           "Extrapolation", "Interpolation", "Key", "Tangent", "bounds_problem",
           "resolve_slopes", "rule_and_slope"]


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
        return self in PERIODIC


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
        for name in TCB_FIELDS:
            v = getattr(self, name)
            if v.__class__ is not float or not math.isfinite(v):
                object.__setattr__(self, name, _tcb_parameter(name, v))

    @classmethod
    def make(cls, time: float, value: float, tan_in: Tangent | str | float = Tangent.SMOOTH,
             tan_out: Tangent | str | float = Tangent.SMOOTH, **kw: Any) -> Key:
        """Build a key from ``.anim``-style tangents: a rule name or a fixed slope."""
        in_rule, in_slope = rule_and_slope(tan_in)
        out_rule, out_slope = rule_and_slope(tan_out)
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


TCB_FIELDS = ("tension", "continuity", "bias")


def _tcb_parameter(name: str, v: Any) -> float:
    """A Kochanek–Bartels parameter: a finite number (not a bool, not a text)."""
    if isinstance(v, (bool, str, bytes)) or not isinstance(v, numbers.Real):
        raise TypeError(f"a key's {name} must be a number, got {v!r}")
    value = float(v)
    if not math.isfinite(value):
        raise ValueError(f"a key's {name} must be finite, got {v!r}")
    return value


def rule_and_slope(tan: Tangent | str | float) -> tuple[Tangent, float]:
    if isinstance(tan, Tangent):
        return tan, 0.0
    if isinstance(tan, str):
        return Tangent(tan), 0.0
    slope = float(tan)
    if not math.isfinite(slope):
        raise ValueError("a fixed slope must be finite")
    return Tangent.FIXED, slope


PERIODIC = (Extrapolation.CYCLE, Extrapolation.CYCLE_OFFSET, Extrapolation.BOUNCE)


def resolve_slopes(keys: Sequence[Key], times: FloatArray,
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



def bounds_problem(keys: Sequence[Key]) -> str | None:
    """Why ``keys`` (sorted by time) hold a number a file may not hold, naming the property
    as a project file spells it (``"times"``, ``"values"``, ``"in"``…), or None: times within
    ±:data:`MAX_KEY_TIME` and at least :data:`KEY_TIME_TOLERANCE` apart; values, fixed
    slopes, weights and Kochanek–Bartels parameters within ±:data:`MAX_KEY_VALUE`.

    Within these bounds a channel's spans, slopes and extrapolation stay finite, so no view
    computes a NaN range from them (issue 31)."""
    if not keys:
        return None
    times = np.fromiter((k.time for k in keys), np.float64, len(keys))
    values = np.fromiter((k.value for k in keys), np.float64, len(keys))
    far = np.flatnonzero(np.abs(times) > MAX_KEY_TIME)
    if far.size:
        return f"\"times\" holds {float(times[far[0]])!r}, beyond the limit of ±{MAX_KEY_TIME:g} seconds"
    gaps = np.diff(times)
    if gaps.size and float(gaps.min()) < KEY_TIME_TOLERANCE:
        i = int(np.argmin(gaps))
        return (f"\"times\" holds keys at {float(times[i])!r} and {float(times[i + 1])!r} s, closer than the "
                f"{KEY_TIME_TOLERANCE:g} s that keys of one channel must be apart")
    big = np.flatnonzero(np.abs(values) > MAX_KEY_VALUE)
    if big.size:
        return f"\"values\" holds {float(values[big[0]])!r}, beyond the limit of ±{MAX_KEY_VALUE:g}"
    for k in keys:
        for name, value in (("in", k.in_slope), ("out", k.out_slope), ("in_weight", k.in_weight),
                            ("out_weight", k.out_weight), ("tension", k.tension),
                            ("continuity", k.continuity), ("bias", k.bias)):
            if value is not None and abs(value) > MAX_KEY_VALUE:
                return f"\"{name}\" of the key at {k.time!r} s is {value!r}, beyond the limit of ±{MAX_KEY_VALUE:g}"
    return None
