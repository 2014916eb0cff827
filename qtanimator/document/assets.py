"""Loading the object behind an asset (a character, a skeleton...) by asset kind.

Engines register a loader per kind (the built-in ones in :mod:`qtanimator.document.loaders`,
which imports this registry, never the other way round); the document calls it when a
project is opened. A loader raises FormatError for a source it cannot read.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from qtanimator.document.document import Asset

Loader = Callable[[Asset], Any]

_LOADERS: dict[str, Loader] = {}


def register_loader(kind: str, loader: Loader) -> None:
    _LOADERS[kind] = loader


def load_runtime(asset: Asset) -> Any:
    """The loaded object for ``asset`` by the loader registered for its kind, or None for
    kinds without one (that need no file). The built-in kinds are registered by importing
    :mod:`qtanimator.document.loaders`, whose ``load_runtime`` is this one."""
    loader = _LOADERS.get(asset.kind)
    return loader(asset) if loader is not None else None
