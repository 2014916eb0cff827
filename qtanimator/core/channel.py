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

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from enum import StrEnum
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


@dataclass(frozen=True, eq=False)
class _Compiled:
    times: FloatArray
    values: FloatArray
    slope_in: FloatArray
    slope_out: FloatArray
    # Per span (n - 1 of them): Hermite form ((A u + B) u + C) u + D over u in [0, 1].
    coeffs: FloatArray  # shape (n - 1, 4): A, B, C, D
    inv_dt: FloatArray
    stepped: npt.NDArray[np.bool_]
    any_stepped: bool


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
        array of times.
        """
        if derivative not in (0, 1, 2):
            raise ValueError("derivative must be 0, 1 or 2")
        scalar = np.ndim(t) == 0
        tt = np.asarray(t, dtype=np.float64)
        out = self._evaluate_array(tt.reshape(-1), derivative).reshape(tt.shape)
        return float(out) if scalar else out

    def __call__(self, t: Any, derivative: int = 0) -> Any:
        return self.evaluate(t, derivative)

    def _evaluate_array(self, t: FloatArray, d: int) -> FloatArray:
        n = len(self.keys)
        if n == 0:
            return np.zeros_like(t)
        c = self._compile()
        if n == 1:
            return np.full_like(t, c.values[0] if d == 0 else 0.0)
        t0 = c.times[0]
        t1 = c.times[-1]
        before = t < t0
        after = t > t1
        any_before = bool(before.any())
        any_after = bool(after.any())
        if not (any_before or any_after):
            return self._eval_inside(c, t, d)

        local = t.copy()
        offset = np.zeros_like(t) if d == 0 else None
        sign = None
        fixed_mask = np.zeros(t.shape, dtype=bool)
        fixed_vals = np.zeros_like(t)
        period = t1 - t0
        for mask, mode, is_pre in ((before, self.pre, True), (after, self.post, False)):
            if not mask.any():
                continue
            tm = t[mask]
            if mode in _PERIODIC:
                k = np.floor((tm - t0) / period)
                u = np.clip((tm - t0) - k * period, 0.0, period)
                if mode is Extrapolation.BOUNCE:
                    odd = np.mod(k, 2.0) == 1.0
                    local[mask] = np.where(odd, t1 - u, t0 + u)
                    if d == 1:
                        if sign is None:
                            sign = np.ones_like(t)
                        sign[mask] = np.where(odd, -1.0, 1.0)
                else:
                    local[mask] = t0 + u
                    if mode is Extrapolation.CYCLE_OFFSET and offset is not None:
                        offset[mask] = k * (c.values[-1] - c.values[0])
            else:
                fixed_mask |= mask
                if mode is Extrapolation.LINEAR:
                    slope = c.slope_in[0] if is_pre else c.slope_out[-1]
                    anchor_t, anchor_v = (t0, c.values[0]) if is_pre else (t1, c.values[-1])
                    vals = anchor_v + slope * (tm - anchor_t) if d == 0 else (
                        np.full_like(tm, slope) if d == 1 else np.zeros_like(tm))
                else:
                    anchor_v = c.values[0] if is_pre else c.values[-1]
                    vals = np.full_like(tm, anchor_v if d == 0 else 0.0)
                fixed_vals[mask] = vals
                local[mask] = t0  # any in-range time; overwritten below
        result = self._eval_inside(c, local, d)
        if offset is not None:
            result += offset
        if sign is not None:
            result *= sign
        if fixed_mask.any():
            result[fixed_mask] = fixed_vals[fixed_mask]
        return result

    @staticmethod
    def _eval_inside(c: _Compiled, t: FloatArray, d: int) -> FloatArray:
        times = c.times
        nspan = len(times) - 1
        i = np.searchsorted(times, t, side="right") - 1
        np.clip(i, 0, nspan - 1, out=i)
        u = (t - times[i]) * c.inv_dt[i]
        coef = c.coeffs[i]
        a, b, cc, dd = coef[:, 0], coef[:, 1], coef[:, 2], coef[:, 3]
        if d == 0:
            res = ((a * u + b) * u + cc) * u + dd
            if c.any_stepped:
                # A stepped span holds its first key's value until the next key's time.
                at_end = c.stepped[i] & (u >= 1.0)
                if at_end.any():
                    res[at_end] = c.values[i[at_end] + 1]
            return res
        if d == 1:
            return ((3.0 * a * u + 2.0 * b) * u + cc) * c.inv_dt[i]
        inv = c.inv_dt[i]
        return (6.0 * a * u + 2.0 * b) * inv * inv

    def _compile(self) -> _Compiled:
        if self._compiled:
            return self._compiled[0]
        keys = self.keys
        n = len(keys)
        times = np.array([k.time for k in keys], dtype=np.float64)
        values = np.array([k.value for k in keys], dtype=np.float64)
        s_in, s_out = _resolve_slopes(keys, times, values)
        if n >= 2:
            dt = np.diff(times)
            p0, p1 = values[:-1], values[1:]
            interp = [k.interpolation for k in keys[:-1]]
            cubic = np.array([m is Interpolation.CUBIC for m in interp])
            linear = np.array([m is Interpolation.LINEAR for m in interp])
            stepped = np.array([m is Interpolation.CONSTANT for m in interp])
            v0 = dt * s_out[:-1]
            v1 = dt * s_in[1:]
            A = np.where(cubic, 2 * p0 - 2 * p1 + v0 + v1, 0.0)
            B = np.where(cubic, -3 * p0 + 3 * p1 - 2 * v0 - v1, 0.0)
            C = np.where(cubic, v0, np.where(linear, p1 - p0, 0.0))
            coeffs = np.stack([A, B, C, p0], axis=1)
            inv_dt = 1.0 / dt
        else:
            coeffs = np.zeros((0, 4))
            inv_dt = np.zeros(0)
            stepped = np.zeros(0, dtype=bool)
        comp = _Compiled(times, values, s_in, s_out, np.ascontiguousarray(coeffs), inv_dt,
                         stepped, bool(stepped.any()))
        self._compiled.append(comp)
        return comp

    # ------------------------------------------------------------- persistence
    def to_dict(self) -> dict[str, Any]:
        return {"pre": self.pre.value, "post": self.post.value,
                "keys": [k.to_dict() for k in self.keys]}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Channel:
        return cls([Key.from_dict(k) for k in d.get("keys", [])],
                   d.get("pre", "constant"), d.get("post", "constant"))


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
