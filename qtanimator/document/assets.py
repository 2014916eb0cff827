"""Loading the object behind an asset (a character, a skeleton...) by asset kind.

Engines register a loader per kind; the document calls it when a project is opened.
A loader raises FormatError for a source it cannot read.
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
    """The loaded object for ``asset``, or None for kinds that need no file."""
    _ensure_builtin_loaders()
    loader = _LOADERS.get(asset.kind)
    return loader(asset) if loader is not None else None


def _ensure_builtin_loaders() -> None:
    # Imported on first use: the loaders pull in every engine, which a plain
    # ``import qtanimator.document`` should not pay for.
    import qtanimator.document.loaders  # noqa: F401
