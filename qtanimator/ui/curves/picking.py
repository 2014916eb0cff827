"""What is under the cursor in the curve plot: keys, tangent handles and curves.

Picking works on what is drawn (scene pixels): the nearest key within
:data:`PICK_RADIUS` (selected keys win a tie), the handles of the selected keys, or the
curve passing closest above or below the cursor.
"""

from __future__ import annotations

import math

import numpy as np
from PySide6.QtCore import QPointF

from qtanimator.core.channel import Channel
from qtanimator.ui.curves.canvas import CurveCanvas
from qtanimator.ui.curves.drags import handle_extents
from qtanimator.ui.curves.items import HANDLE_SIZE, MAX_HANDLES, handle_offsets, map_points

PICK_RADIUS = 7.0       # pixels: how close a click must be to a key or handle
CURVE_PICK_RADIUS = 8.0  # pixels: how close to a curve Ctrl+click must be


class CurvePicking(CurveCanvas):
    """Hit tests of the curve view."""

    def _key_frames(self, cid: str, ch: Channel) -> np.ndarray:
        d = self._drawings.get(cid)
        if d is not None and d.channel is ch and d.fps == self.fps:
            return d.frames
        return ch.times * self.fps

    def key_at(self, scene: QPointF, radius: float = PICK_RADIUS) -> tuple[str, int] | None:
        """The key drawn nearest to ``scene`` within ``radius`` pixels (selected keys win
        a tie). Each channel looks only at its keys within ``radius`` in time."""
        tr = self.view_to_scene()
        best: tuple[float, str, int] | None = None
        reach = radius / abs(tr.m11()) if tr.m11() else math.inf
        fx = self.vb.mapSceneToView(scene).x()
        for cid in self.visible:
            ch = self.doc.channels.get(cid)
            if ch is None or not ch.keys:
                continue
            frames = self._key_frames(cid, ch)
            i0 = int(np.searchsorted(frames, fx - reach, side="left"))
            i1 = int(np.searchsorted(frames, fx + reach, side="right"))
            if i1 <= i0:
                continue
            off, scale = self.display_transform(cid)
            px, py = map_points(tr, frames[i0:i1], (ch.values[i0:i1] - off) * scale)
            d = np.hypot(px - scene.x(), py - scene.y())
            j = int(np.argmin(d))
            i = i0 + j
            # Prefer selected keys when two overlap.
            dist = float(d[j]) - (0.5 if i in self.selection.get(cid, ()) else 0.0)
            if d[j] <= radius and (best is None or dist < best[0]):
                best = (dist, cid, i)
        return None if best is None else (best[1], best[2])

    def handle_positions(self, cid: str, index: int) -> tuple[QPointF, QPointF, QPointF]:
        """Scene positions of a key and its in and out handle ends."""
        ch = self.doc.channels[cid]
        off, scale = self.display_transform(cid)
        tr = self.view_to_scene()
        s_in, s_out = ch.slopes()
        k = scale / self.fps
        x = np.array([ch.keys[index].time * self.fps])
        y = np.array([(ch.keys[index].value - off) * scale])
        px, py = map_points(tr, x, y)
        ext = handle_extents(ch)
        e_in, e_out = (None, None) if ext is None else (ext[0][index:index + 1] * self.fps,
                                                       ext[1][index:index + 1] * self.fps)
        ox, oy = handle_offsets(tr, np.array([s_out[index] * k]), e_out)
        ix, iy = handle_offsets(tr, np.array([s_in[index] * k]), e_in)
        key = QPointF(px[0], py[0])
        return key, QPointF(px[0] - ix[0], py[0] - iy[0]), QPointF(px[0] + ox[0], py[0] + oy[0])

    def handle_at(self, scene: QPointF) -> tuple[str, int, str] | None:
        best: tuple[float, str, int, str] | None = None
        for cid, idx in self.selection.items():
            # Handles are drawn (so can be taken) for at most MAX_HANDLES keys per channel.
            if cid not in self.doc.channels or cid not in self.visible or len(idx) > MAX_HANDLES:
                continue
            for i in idx:
                _key, hin, hout = self.handle_positions(cid, i)
                for side, h in (("in", hin), ("out", hout)):
                    d = math.hypot(h.x() - scene.x(), h.y() - scene.y())
                    if d <= max(PICK_RADIUS, HANDLE_SIZE) and (best is None or d < best[0]):
                        best = (d, cid, i, side)
        return None if best is None else (best[1], best[2], best[3])

    def curve_at(self, scene: QPointF) -> str | None:
        """The visible channel whose curve passes closest (vertically) to ``scene``."""
        tr = self.view_to_scene()
        view = self.vb.mapSceneToView(scene)
        t = view.x() / self.fps
        best: tuple[float, str] | None = None
        for cid in self.visible:
            ch = self.doc.channels.get(cid)
            if ch is None or not ch.keys:
                continue
            off, scale = self.display_transform(cid)
            y = (ch.evaluate(t) - off) * scale
            _px, py = map_points(tr, np.array([view.x()]), np.array([y]))
            d = abs(float(py[0]) - scene.y())
            if d <= CURVE_PICK_RADIUS and (best is None or d < best[0]):
                best = (d, cid)
        return None if best is None else best[1]

