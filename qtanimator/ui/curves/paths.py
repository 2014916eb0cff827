"""Channels as QPainterPaths in view coordinates (x in frames, y in the channel's value).

A cubic Hermite span ``[t0, t1]`` with values ``p0, p1`` and slopes ``m0`` (out of key i),
``m1`` (into key i+1) is exactly the cubic Bézier with control points ``(t0, p0)``,
``(t0 + Δt/3, p0 + m0·Δt/3)``, ``(t1 − Δt/3, p1 − m1·Δt/3)``, ``(t1, p1)``: its x control
points are evenly spaced, so x is linear in the Bézier parameter. So a channel is drawn
from one path built once per channel object (:func:`bezier_path`) that the plot's
transform maps to pixels; Qt flattens each cubic to the pixels it covers.

A weighted span (a key with handle lengths, see :class:`~qtanimator.core.channel.Key`) is
a cubic Bézier in time and value already: its control points are drawn as they are
(``Channel.span_handles`` gives their extents along time, clamped as evaluation clamps
them), so the path is exact for it too.

When keys are denser than the pixels (a long clip zoomed out), :func:`reduced_path` draws
a polyline through a subset of points on the curve instead: one per column of a few
pixels where the curve is straight to within half a pixel, up to three (adding the
column's lowest and highest value) where it bends, so a redraw costs what the screen can
show, not what the channel holds.

Extrapolation is built from the keyed path (:func:`extrapolation_path`): copies shifted by
whole periods (cycle), shifted in time and value (cycle_offset), mirrored in time on odd
periods (bounce), or a straight line (constant, linear), out to a given range.

Paths are built from numpy arrays through ``QDataStream`` (Qt's binary form of a path),
with no Python call per element.
"""

from __future__ import annotations

import math
import operator
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from PySide6.QtCore import QByteArray, QDataStream
from PySide6.QtGui import QPainterPath, QTransform

from qtanimator.core.channel import Channel, Extrapolation, Interpolation

FloatArray = npt.NDArray[np.float64]

#: QPainterPath element types, as QDataStream writes them.
MOVE_TO, LINE_TO, CURVE_TO, CURVE_DATA = 0, 1, 2, 3
#: Beyond this many copies of the keyed path, extrapolation is sampled per pixel column.
MAX_COPIES = 256

_ELEMENT = np.dtype([("type", ">i4"), ("x", ">f8"), ("y", ">f8")])
_KIND_CUBIC, _KIND_LINEAR, _KIND_CONSTANT = 0, 1, 2


def path_from_elements(types: npt.ArrayLike, x: npt.ArrayLike, y: npt.ArrayLike) -> QPainterPath:
    """A QPainterPath from element arrays (types MOVE_TO, LINE_TO, CURVE_TO, CURVE_DATA).

    A CURVE_TO element is the first control point of a cubic and is followed by two
    CURVE_DATA elements: the second control point and the end point.
    """
    t = np.asarray(types)
    n = int(t.size)
    path = QPainterPath()
    if n == 0:
        return path
    body = np.empty(n, dtype=_ELEMENT)
    body["type"] = t
    body["x"] = x
    body["y"] = y
    moves = np.flatnonzero(t == MOVE_TO)
    c_start = int(moves[-1]) if moves.size else 0
    data = (np.array([n], dtype=">i4").tobytes() + body.tobytes()
            + np.array([c_start, 0], dtype=">i4").tobytes())  # cStart, fill rule (odd-even)
    buffer = QByteArray(data)
    stream = QDataStream(buffer)  # read-only, on a copy of the bytes held by ``buffer``
    stream >> path
    return path


def polyline_path(x: FloatArray, y: FloatArray) -> QPainterPath:
    """One open polyline through the points."""
    if len(x) == 0:
        return QPainterPath()
    types = np.full(len(x), LINE_TO, dtype=np.int32)
    types[0] = MOVE_TO
    return path_from_elements(types, x, y)


_KINDS = {Interpolation.CUBIC: _KIND_CUBIC, Interpolation.LINEAR: _KIND_LINEAR,
          Interpolation.CONSTANT: _KIND_CONSTANT}
_interpolation = operator.attrgetter("interpolation")


@dataclass(frozen=True, eq=False)
class Spans:
    """What drawing needs of a channel, as arrays, computed once per channel object.

    ``v0`` / ``v1`` are the Hermite tangents ``Δt·out[i]`` / ``Δt·in[i+1]`` of each span;
    ``bend`` bounds ``|y''(u)|`` over a cubic span (0 for lines and steps).
    ``weighted`` marks the Bézier spans of a channel with handle lengths (None when it has
    none); ``c1`` / ``c2`` are then every span's inner control points as offsets from its
    first / last key, in frames and values: ``(Δf/3, v0/3)`` and ``(−Δf/3, −v1/3)`` for a
    Hermite span.
    """

    frames: FloatArray
    values: FloatArray
    kinds: npt.NDArray[np.int8]
    v0: FloatArray
    v1: FloatArray
    bend: FloatArray
    weighted: npt.NDArray[np.bool_] | None = None
    c1x: FloatArray | None = None
    c1y: FloatArray | None = None
    c2x: FloatArray | None = None
    c2y: FloatArray | None = None

    @classmethod
    def of(cls, channel: Channel, fps: float) -> Spans:
        times, values = channel.times, channel.values
        frames = times * fps
        if len(times) < 2:
            empty = np.zeros(0)
            return cls(frames, values, np.zeros(0, np.int8), empty, empty, empty)
        s_in, s_out = channel.slopes()
        kinds = np.array(list(map(_KINDS.__getitem__, map(_interpolation, channel.keys[:-1]))), dtype=np.int8)
        dt = np.diff(times)
        v0, v1 = dt * s_out[:-1], dt * s_in[1:]
        p0, p1 = values[:-1], values[1:]
        if channel.is_weighted:
            return cls._weighted(channel, fps, frames, values, kinds, v0, v1, s_in, s_out)
        # y''(u) = 6A·u + 2B over u in [0, 1] is largest at an end of the span.
        big_a = 2 * p0 - 2 * p1 + v0 + v1
        big_b = -3 * p0 + 3 * p1 - 2 * v0 - v1
        bend = np.where(kinds == _KIND_CUBIC, np.maximum(np.abs(2 * big_b), np.abs(6 * big_a + 2 * big_b)), 0.0)
        return cls(frames, values, kinds, v0, v1, bend)

    @classmethod
    def _weighted(cls, channel: Channel, fps: float, frames: FloatArray, values: FloatArray,
                  kinds: npt.NDArray[np.int8], v0: FloatArray, v1: FloatArray, s_in: FloatArray,
                  s_out: FloatArray) -> Spans:
        weighted, h_out, h_in = channel.span_handles()
        weighted = weighted & (kinds == _KIND_CUBIC)
        p0, p1 = values[:-1], values[1:]
        c1x, c1y = h_out * fps, h_out * s_out[:-1]
        c2x, c2y = -h_in * fps, -h_in * s_in[1:]
        # y''(u) of a Bézier is largest at an end: 6·(P2 − 2·P1 + P0) and 6·(P3 − 2·P2 + P1).
        q1, q2 = p0 + c1y, p1 + c2y
        bend = np.where(kinds == _KIND_CUBIC,
                        6.0 * np.maximum(np.abs(q2 - 2 * q1 + p0), np.abs(p1 - 2 * q2 + q1)), 0.0)
        return cls(frames, values, kinds, v0, v1, bend, weighted, c1x, c1y, c2x, c2y)


def bezier_elements(channel: Channel, fps: float,
                    spans: Spans | None = None) -> tuple[npt.NDArray[np.int32], FloatArray, FloatArray]:
    """The exact path of the keyed range as element arrays (see :func:`path_from_elements`).

    Cubic spans are Béziers, linear spans lines, constant (stepped) spans a horizontal then
    a vertical line. A single key is a lone MOVE_TO.
    """
    sp = spans if spans is not None else Spans.of(channel, fps)
    frames, values, kinds = sp.frames, sp.values, sp.kinds
    n = len(frames)
    if n == 0:
        return np.zeros(0, np.int32), np.zeros(0), np.zeros(0)
    if n == 1:
        return np.array([MOVE_TO], np.int32), frames.copy(), values.copy()
    count = _BEZIER_COUNT[kinds]
    end = np.cumsum(count)          # each span's last element (element 0 is the move)
    start = end - count + 1
    total = int(end[-1]) + 1
    types = np.empty(total, np.int32)
    x = np.empty(total)
    y = np.empty(total)
    types[0], x[0], y[0] = MOVE_TO, frames[0], values[0]
    f0, f1 = frames[:-1], frames[1:]
    p0, p1 = values[:-1], values[1:]
    # Every span ends on its key: the last element of a span is (t1, p1).
    types[end] = LINE_TO
    x[end] = f1
    y[end] = p1
    cub = np.flatnonzero(kinds == _KIND_CUBIC)
    if cub.size:
        i = start[cub]
        types[i], types[i + 1], types[i + 2] = CURVE_TO, CURVE_DATA, CURVE_DATA
        if sp.weighted is None:
            third = (f1[cub] - f0[cub]) / 3.0
            x[i] = f0[cub] + third
            y[i] = p0[cub] + sp.v0[cub] / 3.0   # p0 + m0·Δt/3
            x[i + 1] = f1[cub] - third
            y[i + 1] = p1[cub] - sp.v1[cub] / 3.0  # p1 − m1·Δt/3
        else:
            assert sp.c1x is not None and sp.c1y is not None and sp.c2x is not None and sp.c2y is not None
            x[i] = f0[cub] + sp.c1x[cub]
            y[i] = p0[cub] + sp.c1y[cub]
            x[i + 1] = f1[cub] + sp.c2x[cub]
            y[i + 1] = p1[cub] + sp.c2y[cub]
    con = np.flatnonzero(kinds == _KIND_CONSTANT)
    if con.size:
        i = start[con]
        types[i] = LINE_TO
        x[i] = f1[con]
        y[i] = p0[con]
    return types, x, y


_BEZIER_COUNT = np.array([3, 1, 2])  # path elements per cubic, linear, constant span


def bezier_path(channel: Channel, fps: float, spans: Spans | None = None) -> QPainterPath:
    """The keyed range of ``channel`` as an exact path (Béziers, lines and steps)."""
    return path_from_elements(*bezier_elements(channel, fps, spans))


def span_samples(channel: Channel, fps: float, column: float, tolerance: float,
                 spans: Spans | None = None) -> tuple[FloatArray, FloatArray]:
    """Points on the keyed range, in time order, such that the polyline through them stays
    within ``tolerance`` of the curve: every key; inside a cubic span as many as its
    bend needs (a nearly straight span none); a stepped span also just before its jump
    (within ``column`` frames of it). Lines need only their keys."""
    sp = spans if spans is not None else Spans.of(channel, fps)
    frames, values, kinds = sp.frames, sp.values, sp.kinds
    n = len(frames)
    if n < 2:
        return frames.copy(), values.copy()
    # Lines through c evenly spaced points of a curve with |y''| <= M (per u²) are within
    # M / (8 c²) of it.
    need = np.ceil(np.sqrt(sp.bend / (8.0 * max(tolerance, 1e-300))))
    count = np.minimum(np.maximum(need, 1.0), 4096.0).astype(np.int64)
    count[kinds == _KIND_CONSTANT] = 2
    if (count == 1).all():
        return frames, values
    span = np.repeat(np.arange(n - 1), count)
    first = np.cumsum(count) - count
    u = (np.arange(span.size) - first[span]) / count[span]
    width = np.diff(frames)
    con = kinds[span] == _KIND_CONSTANT
    # The second point of a step: at most half a column before the jump.
    u[con & (u > 0)] = np.maximum(0.5, 1.0 - 0.5 * column / width[span[con & (u > 0)]])
    p0, p1 = values[:-1][span], values[1:][span]
    u2 = u * u
    u3 = u2 * u
    y = ((2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * sp.v0[span]
         + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * sp.v1[span])
    y[con] = p0[con]
    lin = kinds[span] == _KIND_LINEAR   # only their keys (u = 0): the Hermite form is off
    y[lin] = p0[lin]
    x = frames[:-1][span] + u * width[span]
    if sp.weighted is not None and sp.weighted.any():
        # Bézier spans: x is not linear in the parameter; both coordinates in Bernstein form.
        assert sp.c1x is not None and sp.c1y is not None and sp.c2x is not None and sp.c2y is not None
        bez = np.flatnonzero(sp.weighted[span])
        sb, ub = span[bez], u[bez]
        vb = 1.0 - ub
        w0, w1, w2, w3 = vb * vb * vb, 3.0 * vb * vb * ub, 3.0 * vb * ub * ub, ub * ub * ub
        f0, f1 = frames[:-1][sb], frames[1:][sb]
        q0, q3 = values[:-1][sb], values[1:][sb]
        x[bez] = w0 * f0 + w1 * (f0 + sp.c1x[sb]) + w2 * (f1 + sp.c2x[sb]) + w3 * f1
        y[bez] = w0 * q0 + w1 * (q0 + sp.c1y[sb]) + w2 * (q3 + sp.c2y[sb]) + w3 * q3
    return np.append(x, frames[-1]), np.append(y, values[-1])


def reduce_columns(x: FloatArray, y: FloatArray, column: float, tolerance: float) -> tuple[FloatArray, FloatArray]:
    """The points (x sorted) a polyline needs at a resolution of ``column`` in x and
    ``tolerance`` in y: a subsequence of them, one to three per ``column``-wide bin.

    Every bin keeps its last point. A bin whose points all lie within ``tolerance`` of
    the line from the previous bin's last point to its own last point keeps nothing else;
    a bin that bends more (a peak, a step, noise) also keeps its lowest and its highest
    point, so the polyline still spans the bin's whole range of values.
    """
    n = len(x)
    if n < 3:
        return x, y
    col = np.floor(x / column).astype(np.int64)
    starts = np.flatnonzero(np.concatenate(([True], col[1:] != col[:-1])))
    ends = np.append(starts[1:], n) - 1
    counts = ends - starts + 1
    bin_of = np.repeat(np.arange(len(starts)), counts)
    # The chord from the previous bin's last point to this bin's last point.
    ex, ey = x[ends], y[ends]
    sx = np.concatenate((x[:1], ex[:-1]))
    sy = np.concatenate((y[:1], ey[:-1]))
    run = ex - sx
    slope = np.divide(ey - sy, run, out=np.zeros_like(run), where=run > 0)
    off = np.abs(y - (sy[bin_of] + slope[bin_of] * (x - sx[bin_of])))
    bent = np.maximum.reduceat(off, starts) > tolerance
    keep = np.zeros(n, dtype=bool)
    keep[0] = True
    keep[ends] = True
    if bent.any():
        index = np.arange(n)
        lo = np.minimum.reduceat(y, starts)[bin_of]
        hi = np.maximum.reduceat(y, starts)[bin_of]
        at_lo = np.minimum.reduceat(np.where(y == lo, index, n), starts)
        at_hi = np.minimum.reduceat(np.where(y == hi, index, n), starts)
        keep[at_lo[bent]] = True
        keep[at_hi[bent]] = True
    return x[keep], y[keep]


def reduced_path(channel: Channel, fps: float, column: float, tolerance: float,
                 spans: Spans | None = None) -> QPainterPath:
    """The keyed range drawn per ``column`` frames (see :func:`reduce_columns`), from the
    exact first key to the exact last key."""
    x, y = span_samples(channel, fps, column, tolerance, spans)
    return polyline_path(*reduce_columns(x, y, column, tolerance))


def extrapolation_path(channel: Channel, fps: float, keyed: QPainterPath, x0: float, x1: float,
                       column: float | None = None, tolerance: float = 0.0) -> QPainterPath:
    """Pre and post extrapolation of ``channel`` over frames ``[x0, x1]`` (two subpaths).

    ``keyed`` is the path of the keyed range (:func:`bezier_path` or :func:`reduced_path`);
    periodic modes repeat it. When more than :data:`MAX_COPIES` periods would be needed,
    the extrapolation is sampled per ``column`` frames instead (as :func:`reduced_path`).
    """
    out = QPainterPath()
    if not channel.keys or not x1 > x0:
        return out
    f0 = float(channel.times[0]) * fps
    f1 = float(channel.times[-1]) * fps
    if x0 < f0:
        _side(out, channel, fps, keyed, x0, min(x1, f0), before=True, column=column, tolerance=tolerance)
    if x1 > f1:
        _side(out, channel, fps, keyed, max(x0, f1), x1, before=False, column=column, tolerance=tolerance)
    return out


def _side(out: QPainterPath, channel: Channel, fps: float, keyed: QPainterPath, a: float, b: float,
          before: bool, column: float | None, tolerance: float) -> None:
    mode = channel.pre if before else channel.post
    times, values = channel.times, channel.values
    t0, t1 = float(times[0]), float(times[-1])
    f0, f1 = t0 * fps, t1 * fps
    p0, p1 = float(values[0]), float(values[-1])
    if len(times) == 1 or not mode.periodic:
        # A straight line from the end key (constant, linear; a single key is constant).
        s_in, s_out = channel.slopes()
        if before:
            slope = float(s_in[0]) if mode is Extrapolation.LINEAR and len(times) > 1 else 0.0
            out.moveTo(a, p0 + slope * (a / fps - t0))
            out.lineTo(f0, p0)
        else:
            slope = float(s_out[-1]) if mode is Extrapolation.LINEAR and len(times) > 1 else 0.0
            out.moveTo(f1, p1)
            out.lineTo(b, p1 + slope * (b / fps - t1))
        return
    period = f1 - f0
    rise = p1 - p0 if mode is Extrapolation.CYCLE_OFFSET else 0.0
    # The periods that overlap [a, b]: k < 0 before the keys, k > 0 after them.
    first, last = math.floor((a - f0) / period), math.floor((b - f0) / period)
    ks = range(first, min(last, -1) + 1) if before else range(max(first, 1), last + 1)
    if not ks:
        return
    if len(ks) > MAX_COPIES and column is not None:
        _sampled_side(out, channel, fps, ks, before, column, tolerance)
        return
    ks = ks[-MAX_COPIES:] if before else ks[:MAX_COPIES]
    # Joined to the keyed range's end key when the copies reach it.
    adjacent = ks[-1] == -1 if before else ks[0] == 1
    side = QPainterPath()
    started = not before and adjacent
    if started:
        side.moveTo(f1, p1)
    mirror_reversed = keyed.toReversed() if mode is Extrapolation.BOUNCE else None
    for k in ks:
        if mirror_reversed is not None and k % 2:
            # Odd periods of a bounce run the keys backwards: x -> f0 + f1 + k·period − x.
            copy = QTransform(-1.0, 0.0, 0.0, 1.0, f0 + f1 + k * period, 0.0).map(mirror_reversed)
        else:
            copy = keyed.translated(k * period, k * rise)
        if started:
            # One subpath: a cycle's jump is drawn and the dashes run on. (connectPath
            # drops a lone trailing moveTo, so the jump is an explicit line.)
            side.lineTo(copy.elementAt(0).x, copy.elementAt(0).y)
            side.connectPath(copy)
        else:
            side = copy
            started = True
    if before and adjacent:
        side.lineTo(f0, p0)
    out.addPath(side)


def _sampled_side(out: QPainterPath, channel: Channel, fps: float, ks: range, before: bool,
                  column: float, tolerance: float) -> None:
    """Periods ``ks`` of a periodic extrapolation as one polyline reduced per ``column``.

    Periods at least a column wide: the keyed range's points (reduced per column first)
    repeated as the mode says, then reduced per column. Narrower periods: every column
    holds whole periods, so it shows the band between their lowest and highest values.
    """
    mode = channel.pre if before else channel.post
    f0 = float(channel.times[0]) * fps
    f1 = float(channel.times[-1]) * fps
    period = f1 - f0
    rise = float(channel.values[-1] - channel.values[0]) if mode is Extrapolation.CYCLE_OFFSET else 0.0
    x, y = span_samples(channel, fps, column, tolerance)
    a, b = f0 + ks.start * period, f0 + ks.stop * period
    if period < column:
        cols = np.arange(math.floor(a / column), math.floor(b / column) + 1, dtype=np.float64)
        left, right = cols * column, (cols + 1.0) * column
        k_lo = np.floor((np.maximum(left, a) - f0) / period)
        k_hi = np.floor((np.minimum(right, b) - f0) / period)
        lo = float(y.min()) + np.minimum(k_lo * rise, k_hi * rise)
        hi = float(y.max()) + np.maximum(k_lo * rise, k_hi * rise)
        flip = (np.arange(len(cols)) % 2).astype(bool)
        rx = np.repeat(np.clip((cols + 0.5) * column, a, b), 2)
        ry = np.column_stack([np.where(flip, hi, lo), np.where(flip, lo, hi)]).ravel()
    else:
        x, y = reduce_columns(x, y, column, tolerance)
        k = np.arange(ks.start, ks.stop, dtype=np.float64)[:, None]
        xs = x + k * period
        ys = np.broadcast_to(y, xs.shape) + k * rise
        if mode is Extrapolation.BOUNCE:
            odd = (np.abs(k[:, 0]) % 2) == 1
            xs[odd] = (f0 + f1 + k[odd] * period) - x[::-1]
            ys[odd] = y[::-1]
        rx, ry = reduce_columns(xs.ravel(), ys.ravel(), column, tolerance)
    if before and ks[-1] == -1:
        rx, ry = np.append(rx, f0), np.append(ry, float(channel.values[0]))
    elif not before and ks[0] == 1:
        rx, ry = np.insert(rx, 0, f1), np.insert(ry, 0, float(channel.values[-1]))
    out.addPath(polyline_path(rx, ry))
