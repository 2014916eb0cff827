"""The project document: assets, the channels that animate them, and parameters.

The document is plain data plus change notification. Only commands
(:mod:`qtanimator.document.commands`) call the mutating methods whose names start with
``apply_``; widgets read the document and subscribe to its events. :attr:`Document.channels`
and :attr:`Document.parameters` are read-only views (``dict(doc.channels)`` for a copy);
set up a document's content through commands (``SetChannels(...).do(doc)``) or, when
loading, through the constructor.

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
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

from qtanimator.core.channel import Channel
from qtanimator.document.parameters import PROJECT, defaults

DEFAULT_FPS = float(PROJECT["fps"].default)

#: Parameters every document has, with their defaults (a view of the schema,
#: :data:`qtanimator.document.parameters.PROJECT`, which also holds their ranges).
PROJECT_DEFAULTS: dict[str, Any] = defaults(PROJECT)


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


_NO_CHANNELS: Mapping[str, float] = MappingProxyType({})


@dataclass(frozen=True)
class DocumentChange:
    """Everything one command (or one batch of edits) changed: one notification per command.

    ``channels`` maps each changed channel id to the earliest time whose evaluation may
    differ (caches keep what lies before it; ``-inf`` means everything, ``+inf`` that the
    channel was set to an equal value). ``parameters`` and ``assets`` are the changed
    parameter paths and asset ids; ``reset`` says the whole document was replaced.
    """

    channels: Mapping[str, float] = field(default_factory=lambda: _NO_CHANNELS)
    parameters: frozenset[str] = frozenset()
    assets: frozenset[str] = frozenset()
    reset: bool = False

    @property
    def time_from(self) -> float:
        """The earliest affected time over every changed channel (+inf without channels)."""
        return min(self.channels.values(), default=math.inf)

    def channel_assets(self) -> frozenset[str]:
        """The ids of the assets whose channels changed."""
        return frozenset(cid.split("/", 1)[0] for cid in self.channels)

    def touches_asset(self, asset_id: str) -> bool:
        """True when the asset itself or any of its channels changed (or on reset)."""
        return self.reset or asset_id in self.assets or asset_id in self.channel_assets()

    def channel_time_from(self, asset_id: str) -> float:
        """The earliest affected time among one asset's changed channels (+inf if none)."""
        prefix = asset_id + "/"
        return min((t for cid, t in self.channels.items() if cid.startswith(prefix)), default=math.inf)

    def merged(self, other: DocumentChange) -> DocumentChange:
        """The union of two changes (what a view sees when it catches up on both)."""
        channels = dict(self.channels)
        for cid, t in other.channels.items():
            channels[cid] = min(t, channels.get(cid, math.inf))
        return DocumentChange(MappingProxyType(channels), self.parameters | other.parameters,
                              self.assets | other.assets, self.reset or other.reset)

    def __bool__(self) -> bool:
        return bool(self.channels or self.parameters or self.assets or self.reset)


class _PendingChange:
    """What a batch has changed so far (see :meth:`Document.batch`)."""

    def __init__(self) -> None:
        self.channels: dict[str, float] = {}
        self.parameters: set[str] = set()
        self.assets: set[str] = set()

    def freeze(self) -> DocumentChange:
        return DocumentChange(MappingProxyType(self.channels), frozenset(self.parameters),
                              frozenset(self.assets))


Listener = Callable[[DocumentChange], None]


class Document:
    """The one document every editor shows."""

    def __init__(self, *, channels: Mapping[str, Channel] | None = None,
                 parameters: Mapping[str, Any] | None = None) -> None:
        """A new document; ``channels`` and ``parameters`` are its initial content (what a
        loader read; the parameters default to :data:`PROJECT_DEFAULTS`, which fill in any
        missing). After that only commands change them (the ``apply_*`` methods)."""
        self.assets: dict[str, Asset] = {}
        self._set_content(dict(channels or {}), {**PROJECT_DEFAULTS, **(parameters or {})})
        self.runtime: dict[str, Any] = {}
        #: View state such as the 3D camera: saved with the project, never an edit (no
        #: command, no undo step, not part of :meth:`state`). See :meth:`set_view_state`.
        self.view_state: dict[str, Any] = {}
        #: Derived data that belongs to this document and dies with it: the simulation
        #: caches (``"pendulums"``: :func:`qtanimator.document.character2d.simulation`).
        #: Never saved, never an edit; the caches invalidate themselves on changes.
        self.caches: dict[str, Any] = {}
        self.path: str | None = None
        self._listeners: list[Listener] = []
        self._pending: _PendingChange | None = None
        self._batch_depth = 0

    # ----------------------------------------------------------- notification
    def subscribe(self, listener: Listener) -> None:
        self._listeners.append(listener)

    def unsubscribe(self, listener: Listener) -> None:
        if listener in self._listeners:
            self._listeners.remove(listener)

    def emit(self, change: DocumentChange) -> None:
        """Tell every listener about ``change`` (inside a batch: fold it into the batch)."""
        if self._pending is not None and not change.reset:
            self._record(change)
            return
        for listener in list(self._listeners):
            listener(change)

    @contextmanager
    def batch(self) -> Iterator[None]:
        """Fold every change made inside into one notification, sent when the outermost
        batch ends (also when it ends with an exception: what was changed is announced).
        Commands run inside a batch, so a command announces one change however many
        channels it touches."""
        self._batch_depth += 1
        if self._pending is None:
            self._pending = _PendingChange()
        try:
            yield
        finally:
            self._batch_depth -= 1
            if self._batch_depth == 0:
                pending, self._pending = self._pending, None
                change = pending.freeze() if pending is not None else DocumentChange()
                if change:
                    self.emit(change)

    def _record(self, change: DocumentChange) -> None:
        pending = self._pending
        assert pending is not None
        for cid, t in change.channels.items():
            pending.channels[cid] = min(t, pending.channels.get(cid, math.inf))
        pending.parameters.update(change.parameters)
        pending.assets.update(change.assets)

    # ------------------------------------------------------------------ reads
    @property
    def channels(self) -> Mapping[str, Channel]:
        """Channel id → :class:`Channel`, read only (a live view: commands change it)."""
        return self._channels_view

    @property
    def parameters(self) -> Mapping[str, Any]:
        """Dotted path → JSON value, read only (a live view: commands change it)."""
        return self._parameters_view

    def _set_content(self, channels: dict[str, Channel], parameters: dict[str, Any]) -> None:
        # The private dicts are written only by the apply_* methods (and here); readers get
        # views made once, so a read costs a dict look-up, never a copy.
        self._channels = channels
        self._parameters = parameters
        self._channels_view: Mapping[str, Channel] = MappingProxyType(channels)
        self._parameters_view: Mapping[str, Any] = MappingProxyType(parameters)

    def __getstate__(self) -> dict[str, Any]:
        # the views do not pickle (copy.copy and pickle go through here); they are rebuilt
        state = dict(self.__dict__)
        del state["_channels_view"], state["_parameters_view"]
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._set_content(self._channels, self._parameters)

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
            self._channels.pop(cid, None)
        else:
            self._channels[cid] = channel
        self.emit(DocumentChange(channels=MappingProxyType({cid: time_from})))

    def apply_parameter(self, path: str, value: Any) -> None:
        """Set (or with None remove) one parameter and announce it."""
        if value is None:
            self._parameters.pop(path, None)
        else:
            self._parameters[path] = value
        self.emit(DocumentChange(parameters=frozenset((path,))))

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
        self.emit(DocumentChange(assets=frozenset((asset_id,))))

    def set_view_state(self, key: str, value: Any) -> None:
        """Remember how an editor looks at the document (camera, zoom). Not an edit."""
        self.view_state[key] = value

    def replace_all(self, other: Document) -> None:
        """Take over another document's content (used by File > Open and New)."""
        self.assets = other.assets
        self._set_content(other._channels, other._parameters)
        self.runtime = other.runtime
        self.view_state = other.view_state
        self.path = other.path
        if self._pending is not None:
            self._pending = _PendingChange()  # a reset supersedes what the batch changed
        self.emit(DocumentChange(reset=True))

    # -------------------------------------------------------------- snapshots
    def state(self) -> dict[str, Any]:
        """Everything authored, as comparable plain data (tests and autosave use it)."""
        return {
            "assets": [
                {"id": a.id, "kind": a.kind, "source": a.source, "properties": _deep_copy(a.properties)}
                for a in self.assets.values()
            ],
            "channels": {cid: ch.to_dict() for cid, ch in self.channels.items()},
            "parameters": _deep_copy(self._parameters),
        }


def _deep_copy(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _deep_copy(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_deep_copy(v) for v in value]
    return value
