"""Registers the loader of every asset kind the program knows.

Each engine adds its line here: ``register_loader("character2d", load_character_asset)``.
"""

from __future__ import annotations

from qtanimator.document.assets import register_loader
from qtanimator.document.character2d import load_character_asset
from qtanimator.document.character3d import ASSET_KIND as CHARACTER3D
from qtanimator.document.character3d import load_character3d_asset
from qtanimator.document.cloth import load_cloth_asset

register_loader("cloth", load_cloth_asset)
register_loader(CHARACTER3D, load_character3d_asset)
register_loader("character2d", load_character_asset)
