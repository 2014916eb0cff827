"""The project document: assets, the channels that animate them, and parameters.

The document is plain data plus change notification. Only commands
(:mod:`qtanimator.document.commands`) call the mutating methods whose names start with
``apply_``; widgets read the document and subscribe to its events.

Vocabulary
----------
asset
    Something in the scene: a 2D character, a 3D skeleton with an optional skin, a cloth,
    a light. An :class:`Asset` records its ``kind``, an optional ``source`` file and a dict
    of authored ``properties``. The object loaded from the source (a ``Character``, a
    ``Skeleton``…) lives in :attr:`Document.runtime`, rebuilt on load, never saved.
channel id
    ``"<asset>/<joint>/<dof>"``: the asset id, the joint name ("" for asset-level channels
    such as a character's ``x`` / ``y``), and the DOF name. See :func:`channel_id`.
parameter
    A JSON value under a dotted path, e.g. ``"fps"`` or ``"cloth1.wind.speed"``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

from qtanimator.core.channel import Channel

DEFAULT_FPS = 60.0

#: Parameters every document has, with their defaults.
PROJECT_DEFAULTS: dict[str, Any] = {
    "fps": DEFAULT_FPS,
    "frame_start": 0,
    "frame_end": 240,
}


def channel_id(asset: str, joint: str, dof: str) -> str:
    """Build a channel id. Asset ids and DOF names never contain '/'; joint names may."""
    if "/" in asset or "/" in dof:
        raise ValueError("asset ids and DOF names may not contain '/'")
    return f"{asset}/{joint}/{dof}"


def split_channel_id(cid: str) -> tuple[str, str, str]:
    """Inverse of :func:`channel_id`: ``(asset, joint, dof)``."""
    asset, rest = cid.split("/", 1)
    joint, dof = rest.rsplit("/", 1)
    return asset, joint, dof


@dataclass
class Asset:
    """One thing in the scene. ``source`` is an absolute path at run time (or None)."""

    id: str
    kind: str
    source: str | None = None
    properties: dict[str, Any] = field(default_factory=dict)

    def copy(self) -> Asset:
        return Asset(self.id, self.kind, self.source, _deep_copy(self.properties))


@dataclass(frozen=True)
class ChangeEvent:
    """What changed. ``kind`` is 'channel', 'parameter', 'asset' or 'reset'.

    For channels, ``time_from`` is the earliest time whose evaluation may differ (caches
    keep what lies before it); ``-inf`` means everything.
    """

    kind: str
    key: str = ""
    time_from: float = -math.inf


Listener = Callable[[ChangeEvent], None]


class Document:
    """The one document every editor shows."""

    def __init__(self) -> None:
        self.assets: dict[str, Asset] = {}
        self.channels: dict[str, Channel] = {}
        self.parameters: dict[str, Any] = dict(PROJECT_DEFAULTS)
        self.runtime: dict[str, Any] = {}
        #: View state such as the 3D camera: saved with the project, never an edit (no
        #: command, no undo step, not part of :meth:`state`). See :meth:`set_view_state`.
        self.view_state: dict[str, Any] = {}
        self.path: str | None = None
        self._listeners: list[Listener] = []

    # ----------------------------------------------------------- notification
    def subscribe(self, listener: Listener) -> None:
        self._listeners.append(listener)

    def unsubscribe(self, listener: Listener) -> None:
        if listener in self._listeners:
            self._listeners.remove(listener)

    def emit(self, event: ChangeEvent) -> None:
        for listener in list(self._listeners):
            listener(event)

    # ------------------------------------------------------------------ reads
    @property
    def fps(self) -> float:
        return float(self.parameters.get("fps", DEFAULT_FPS))

    @property
    def frame_range(self) -> tuple[int, int]:
        return int(self.parameters.get("frame_start", 0)), int(self.parameters.get("frame_end", 240))

    def frame_to_time(self, frame: float) -> float:
        return frame / self.fps

    def time_to_frame(self, time: float) -> float:
        return time * self.fps

    def parameter(self, path: str, default: Any = None) -> Any:
        return self.parameters.get(path, default)

    def channels_of(self, asset: str) -> Iterator[tuple[str, Channel]]:
        prefix = asset + "/"
        for cid, ch in self.channels.items():
            if cid.startswith(prefix):
                yield cid, ch

    def unique_asset_id(self, base: str) -> str:
        stem = "".join(c if (c.isalnum() or c in "-_.") else "_" for c in base) or "asset"
        name, i = stem, 2
        while name in self.assets:
            name = f"{stem}_{i}"
            i += 1
        return name

    # ------------------------------------------------- mutations (commands only)
    def apply_channel(self, cid: str, channel: Channel | None, time_from: float = -math.inf) -> None:
        """Set (or with None remove) one channel and announce it."""
        if channel is None:
            self.channels.pop(cid, None)
        else:
            self.channels[cid] = channel
        self.emit(ChangeEvent("channel", cid, time_from))

    def apply_parameter(self, path: str, value: Any) -> None:
        """Set (or with None remove) one parameter and announce it."""
        if value is None:
            self.parameters.pop(path, None)
        else:
            self.parameters[path] = value
        self.emit(ChangeEvent("parameter", path))

    def apply_asset(self, asset_id: str, asset: Asset | None, runtime: Any = None,
                    index: int | None = None) -> None:
        """Add, replace (or with None remove) an asset and its loaded object."""
        if asset is None:
            self.assets.pop(asset_id, None)
            self.runtime.pop(asset_id, None)
        else:
            if index is not None and asset_id not in self.assets:
                items = list(self.assets.items())
                items.insert(index, (asset_id, asset))
                self.assets = dict(items)
            else:
                self.assets[asset_id] = asset
            if runtime is not None:
                self.runtime[asset_id] = runtime
        self.emit(ChangeEvent("asset", asset_id))

    def set_view_state(self, key: str, value: Any) -> None:
        """Remember how an editor looks at the document (camera, zoom). Not an edit."""
        self.view_state[key] = value

    def replace_all(self, other: Document) -> None:
        """Take over another document's content (used by File > Open and New)."""
        self.assets = other.assets
        self.channels = other.channels
        self.parameters = other.parameters
        self.runtime = other.runtime
        self.view_state = other.view_state
        self.path = other.path
        self.emit(ChangeEvent("reset"))

    # -------------------------------------------------------------- snapshots
    def state(self) -> dict[str, Any]:
        """Everything authored, as comparable plain data (tests and autosave use it)."""
        return {
            "assets": [
                {"id": a.id, "kind": a.kind, "source": a.source, "properties": _deep_copy(a.properties)}
                for a in self.assets.values()
            ],
            "channels": {cid: ch.to_dict() for cid, ch in self.channels.items()},
            "parameters": _deep_copy(self.parameters),
        }


def _deep_copy(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _deep_copy(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_deep_copy(v) for v in value]
    return value
