"""What the outliner edits: whether a scene object is hidden or locked, and its name.

Assets keep the two flags as authored properties (``hidden``, ``locked``); the two lights,
which are document parameters rather than assets, keep them as parameters
(``light1.hidden``, ``light1.locked``…). A flag that is off is absent (the property or
parameter is removed), so hiding and showing again gives back exactly the document that
was there. Every change is a command (one undo step) and is saved with the project.

Hidden objects are not drawn (2D editor, 3D view, renders) and cannot be picked; locked
objects are drawn but cannot be picked or dragged in the views.
"""

from __future__ import annotations

from typing import Any

from qtanimator.document.commands import Command, RenameAsset, SetAssetProperty, SetParameter
from qtanimator.document.document import Document

HIDDEN = "hidden"
LOCKED = "locked"
FLAGS = (HIDDEN, LOCKED)
#: The two lights (``render.gl.lights.LIGHT_NAMES``; repeated here: document imports no render).
LIGHTS = ("light1", "light2")
#: Characters an asset id may hold (the same as :meth:`Document.unique_asset_id` makes).
NAME_EXTRA_CHARACTERS = "-_."


def is_light(target: str) -> bool:
    return target in LIGHTS


def flag(doc: Any, target: str, name: str) -> bool:
    """True when ``target`` (an asset id or a light name) has flag ``name`` set."""
    if is_light(target):
        params = doc if isinstance(doc, dict) else doc.parameters
        return bool(params.get(f"{target}.{name}", False))
    asset = doc.assets.get(target)
    return asset is not None and bool(asset.properties.get(name, False))


def is_hidden(doc: Any, target: str) -> bool:
    return flag(doc, target, HIDDEN)


def is_locked(doc: Any, target: str) -> bool:
    return flag(doc, target, LOCKED)


def pickable(doc: Any, target: str) -> bool:
    """Whether the views may pick (and drag) ``target``: neither hidden nor locked."""
    return not (is_hidden(doc, target) or is_locked(doc, target))


def set_flag_command(doc: Document, target: str, name: str, on: bool) -> Command:
    """Hide / show or lock / unlock an asset or a light: one undo step."""
    if name not in FLAGS:
        raise ValueError(f"unknown flag {name!r} (use {' or '.join(FLAGS)})")
    verb = {(HIDDEN, True): "Hide", (HIDDEN, False): "Show",
            (LOCKED, True): "Lock", (LOCKED, False): "Unlock"}[(name, bool(on))]
    value = True if on else None
    if is_light(target):
        return SetParameter(doc, f"{target}.{name}", value, text=f"{verb} {target}")
    if target not in doc.assets:
        raise KeyError(f"there is no asset called {target!r}")
    return SetAssetProperty(doc, target, name, value, text=f"{verb} {target}")


def name_problem(doc: Document, old: str, new: str) -> str | None:
    """Why ``old`` cannot be renamed ``new`` (a sentence), or None when it can."""
    if old not in doc.assets:
        return f"There is no asset called '{old}'."
    if not new:
        return "A name cannot be empty."
    bad = sorted({c for c in new if not (c.isalnum() or c in NAME_EXTRA_CHARACTERS)})
    if bad:
        return f"A name may hold letters, digits and {' '.join(NAME_EXTRA_CHARACTERS)} only, not {''.join(bad)!r}."
    if new != old and (new in doc.assets or is_light(new)):
        return f"The name '{new}' is already in use."
    return None


def rename_command(doc: Document, old: str, new: str) -> RenameAsset:
    """Rename an asset (its channels and parameters follow); ValueError says why not."""
    problem = name_problem(doc, old, new)
    if problem is not None:
        raise ValueError(problem)
    return RenameAsset(doc, old, new)
