"""Opening and saving documents as JSON projects.

Opening a project whose asset files moved does not fail at once: :func:`open_document_relinked`
looks for each missing file by name beside the project (its folder tree, the folders of
files already found), then asks ``locate`` (the GUI shows a file dialog), and reports what
it relinked. Only a file that is still missing after that makes the open fail.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from qtanimator.document.asset_files import FileRef, find_beside, missing_refs
from qtanimator.document.document import Asset, Document
from qtanimator.formats.errors import FormatError
from qtanimator.formats.project import AssetRecord, ProjectData, load_project, save_project


def to_project_data(doc: Document) -> ProjectData:
    """A snapshot of what a project file stores, cheap enough for the UI thread.

    Channels are immutable values, so a copy of the channel dict is enough (no key is
    copied). Parameters, view state and asset properties are small and copied in depth, so
    the snapshot stays as it was while a worker thread writes it, whatever the document
    does meanwhile (commands replace assets rather than change them, but a copy costs
    nothing and keeps that a convention, not a requirement).
    """
    return ProjectData(
        parameters=copy.deepcopy(dict(doc.parameters)),
        view=copy.deepcopy(doc.view_state),
        assets=[AssetRecord(a.id, a.kind, a.source, copy.deepcopy(a.properties)) for a in doc.assets.values()],
        channels=dict(doc.channels),
    )


def _load_runtime(asset: Asset) -> Any:
    """:func:`qtanimator.document.loaders.load_runtime`, imported on the first open: the
    loaders pull in every engine, which a plain ``import qtanimator.document`` should not pay
    for. (Nothing those import imports this module: no cycle.)"""
    from qtanimator.document.loaders import load_runtime

    return load_runtime(asset)


def document_from_project_data(data: ProjectData, path: str | os.PathLike[str] | None = None) -> Document:
    """Build a document and load every asset's source (FormatError if one fails).

    ``path`` is the project file: an error of a loader that names no file names it."""
    doc = Document(channels=data.channels, parameters=data.parameters)  # defaults fill in the rest
    doc.view_state = dict(data.view)
    for rec in data.assets:
        asset = Asset(rec.id, rec.kind, rec.source, dict(rec.properties))
        doc.assets[asset.id] = asset
        try:
            runtime = _load_runtime(asset)
        except OSError as exc:  # a loader that let a missing or unreadable file through
            raise FormatError(f"asset {asset.id!r}: cannot read {exc.filename or asset.source!r} "
                              f"({exc.strerror or exc}).", rec.source) from exc
        except FormatError as exc:
            if exc.path is not None or path is None:
                raise
            raise FormatError(exc.message, path, exc.line, exc.column) from exc
        except (TypeError, ValueError, KeyError, IndexError, ArithmeticError) as exc:
            # A safety net: the project reader checks the types every loader relies on.
            text = str(exc)
            raise FormatError(f"asset {asset.id!r} ({asset.kind}) has a property of the wrong kind or size "
                              f"({type(exc).__name__}: {text[:120]}).", path) from exc
        if runtime is not None:
            doc.runtime[asset.id] = runtime
    return doc


#: Asked for a missing file: returns the path the user picked, or None to give up.
Locate = Callable[[FileRef], str | None]


@dataclass(frozen=True)
class Relink:
    """A file reference found at a new place: ``how`` is ``"found"`` (by name beside the
    project) or ``"chosen"`` (the user picked it)."""

    ref: FileRef
    new_path: str
    how: str


def open_document(path: str | os.PathLike[str], locate: Locate | None = None) -> Document:
    """Read a project into a new document; the caller's document is never touched."""
    return open_document_relinked(path, locate)[0]


def open_document_relinked(path: str | os.PathLike[str],
                           locate: Locate | None = None) -> tuple[Document, list[Relink]]:
    """:func:`open_document`, finding moved asset files first; returns the relinks made.

    The document holds the new paths (save it to keep them). FormatError as before when a
    file is still missing."""
    data = load_project(path)
    relinks = relink_missing(data, Path(path).resolve().parent, locate)
    doc = document_from_project_data(data, path)
    doc.path = str(Path(path).resolve())
    return doc, relinks


def relink_missing(data: ProjectData, project_dir: Path, locate: Locate | None = None) -> list[Relink]:
    """Point ``data``'s missing file references at files found or chosen by the user.

    For each missing file, in this order: the same relative place under a folder that an
    earlier missing file was found to have moved to (a whole folder moved: ``art/x.skel`` now
    in ``backup/``, so ``art/other/y.skin`` is looked for as ``backup/other/y.skin``); a file
    of the same name in the project's folder tree or those new folders; ``locate``.
    """
    relinks: list[Relink] = []
    folders: list[Path] = [project_dir]
    moves: list[tuple[Path, Path]] = []  # (old folder, new folder)
    resolved: dict[str, str] = {}  # the same missing file referenced twice is asked for once
    for ref in missing_refs(data.assets):
        old = Path(ref.path)
        new = resolved.get(ref.path)
        how = "found"
        if new is None:
            found = _moved_along(old, moves) or find_beside(old.name, folders)
            if found is not None:
                new = str(found)
            elif locate is not None:
                chosen = locate(ref)
                if chosen:
                    new, how = str(Path(chosen).resolve()), "chosen"
        if new is None or not Path(new).exists():
            continue
        if new not in resolved.values():
            moves.append((old.parent, Path(new).parent))
            if Path(new).parent not in folders:
                folders.append(Path(new).parent)  # its neighbours moved along, most likely
        resolved[ref.path] = new
        _set_ref(data, ref, new)
        relinks.append(Relink(ref, new, how))
    return relinks


def _moved_along(old: Path, moves: list[tuple[Path, Path]]) -> Path | None:
    for old_dir, new_dir in moves:
        try:
            candidate = new_dir / old.relative_to(old_dir)
        except ValueError:
            continue
        if candidate.exists():
            return candidate.resolve()
    return None


def _set_ref(data: ProjectData, ref: FileRef, new_path: str) -> None:
    for i, rec in enumerate(data.assets):
        if rec.id != ref.asset_id:
            continue
        if ref.key == "source":
            data.assets[i] = replace(rec, source=new_path)
        else:
            data.assets[i] = replace(rec, properties={**rec.properties, ref.key: new_path})


def save_document(doc: Document, path: str | os.PathLike[str]) -> None:
    """Save atomically and remember the path."""
    save_project(to_project_data(doc), path)
    doc.path = str(Path(path).resolve())
