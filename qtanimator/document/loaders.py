"""Registers the loader of every asset kind the program knows.

Each engine adds its line here: ``register_loader("character2d", load_character_asset)``.
"""

from __future__ import annotations

from qtanimator.document.assets import register_loader  # noqa: F401
