"""Opening and saving documents as JSON projects."""

from __future__ import annotations

import copy
import os
from pathlib import Path

from qtanimator.document.assets import load_runtime
from qtanimator.document.document import PROJECT_DEFAULTS, Asset, Document
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
        parameters=copy.deepcopy(doc.parameters),
        view=copy.deepcopy(doc.view_state),
        assets=[AssetRecord(a.id, a.kind, a.source, copy.deepcopy(a.properties)) for a in doc.assets.values()],
        channels=dict(doc.channels),
    )


def document_from_project_data(data: ProjectData) -> Document:
    """Build a document and load every asset's source (FormatError if one fails)."""
    doc = Document()
    doc.parameters = {**PROJECT_DEFAULTS, **data.parameters}
    doc.view_state = dict(data.view)
    for rec in data.assets:
        asset = Asset(rec.id, rec.kind, rec.source, dict(rec.properties))
        doc.assets[asset.id] = asset
        try:
            runtime = load_runtime(asset)
        except OSError as exc:  # a loader that let a missing or unreadable file through
            raise FormatError(f"asset {asset.id!r}: cannot read {exc.filename or asset.source!r} "
                              f"({exc.strerror or exc}).", rec.source) from exc
        if runtime is not None:
            doc.runtime[asset.id] = runtime
    doc.channels = dict(data.channels)
    return doc


def open_document(path: str | os.PathLike[str]) -> Document:
    """Read a project into a new document; the caller's document is never touched."""
    doc = document_from_project_data(load_project(path))
    doc.path = str(Path(path).resolve())
    return doc


def save_document(doc: Document, path: str | os.PathLike[str]) -> None:
    """Save atomically and remember the path."""
    save_project(to_project_data(doc), path)
    doc.path = str(Path(path).resolve())
