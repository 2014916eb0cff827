"""Registers the loader of every asset kind the program knows.

Each engine adds its line here: ``register_loader(ASSET_KIND, load_…_asset)``. Import
:func:`load_runtime` from here to load an asset with every built-in kind registered.
"""

from __future__ import annotations

from qtanimator.document import character2d, character3d, cloth
from qtanimator.document.assets import load_runtime, register_loader

__all__ = ["load_runtime"]

register_loader(cloth.ASSET_KIND, cloth.load_cloth_asset)
register_loader(character3d.ASSET_KIND, character3d.load_character3d_asset)
register_loader(character2d.ASSET_KIND, character2d.load_character_asset)
