"""The files a project's assets refer to: collecting them into the project folder, and
finding them again when they moved.

An asset refers to files through its ``source`` (a file, or a folder of SVG characters)
and through every property whose name ends in ``_file`` (``skin_file``, ``anim_file``…).
Those references are what :func:`file_refs` lists, what Collect Assets copies, and what a
project opened after its assets moved asks the user to locate.

* :func:`collect_assets` copies every referenced file that lies outside the project folder
  into ``<project folder>/assets/`` (a folder source as a folder; a ``.gltf`` with the
  buffers and images it names beside it) and returns one undoable command that rewrites
  the paths. Undo puts the old paths back; the copies stay on disk (they are harmless, and
  deleting a user's files on undo would not be).
* :func:`find_beside` looks for a moved file by name in the project's folder tree.
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from urllib.parse import unquote

from qtanimator.document.commands import Command
from qtanimator.document.document import Asset, Document

#: Where Collect Assets puts the copies, inside the project folder.
ASSETS_FOLDER = "assets"
#: How many folder entries :func:`find_beside` looks at before it gives up (a project saved
#: in the home folder must not make opening it crawl the whole disk).
SEARCH_LIMIT = 20_000
SEARCH_DEPTH = 4


@dataclass(frozen=True)
class FileRef:
    """One file reference of an asset: ``key`` is ``"source"`` or a ``*_file`` property."""

    asset_id: str
    key: str
    path: str


def is_path_property(name: str, value: Any) -> bool:
    """Asset properties named ``*_file`` hold file paths (as in the project format)."""
    return name.endswith("_file") and isinstance(value, str) and bool(value)


def file_refs(assets: Iterable[Any]) -> list[FileRef]:
    """Every file reference of ``assets`` (:class:`Asset` or project ``AssetRecord``)."""
    refs = []
    for asset in assets:
        if asset.source:
            refs.append(FileRef(asset.id, "source", str(asset.source)))
        for name, value in asset.properties.items():
            if is_path_property(name, value):
                refs.append(FileRef(asset.id, name, value))
    return refs


def with_path(asset: Asset, key: str, path: str) -> Asset:
    """A copy of ``asset`` whose reference ``key`` is ``path``."""
    new = asset.copy()
    if key == "source":
        new.source = path
    else:
        new.properties[key] = path
    return new


def is_inside(path: str | os.PathLike[str], folder: str | os.PathLike[str]) -> bool:
    """True when ``path`` (resolved) lies in ``folder`` (resolved) or one of its sub-folders."""
    try:
        Path(path).resolve().relative_to(Path(folder).resolve())
    except ValueError:
        return False
    return True


# ------------------------------------------------------------------ collect
class SetAssetFiles(Command):
    """Replace the file references of several assets at once (one undo step).

    The loaded objects stay as they are: the files at the new paths are copies of the old.
    """

    def __init__(self, doc: Document, new_assets: dict[str, Asset], text: str = "Collect Assets") -> None:
        self.old = {aid: doc.assets[aid] for aid in new_assets}
        self.new = dict(new_assets)
        self.text = text

    def do(self, doc: Document) -> None:
        for aid, asset in self.new.items():
            doc.apply_asset(aid, asset)

    def undo(self, doc: Document) -> None:
        for aid, asset in self.old.items():
            doc.apply_asset(aid, asset)

    def is_noop(self) -> bool:
        return all(self.old[aid] == asset for aid, asset in self.new.items())


@dataclass
class CollectResult:
    """What :func:`collect_assets` did: the command to push (None when nothing moved), and
    the copies made as (original, copy) pairs."""

    command: SetAssetFiles | None
    copied: list[tuple[str, str]]


def collect_assets(doc: Document, project_dir: str | os.PathLike[str], folder: str = ASSETS_FOLDER) -> CollectResult:
    """Copy every referenced file outside ``project_dir`` into ``project_dir/folder`` and
    return the command that points the assets at the copies (not yet done).

    A file referenced twice is copied once; two different files of the same name get
    ``name-2.ext``, ``name-3.ext``. A copy that already holds the same bytes is reused, so
    collecting twice copies nothing new. Raises OSError when a copy fails (the files copied
    before stay, and no path has changed yet).
    """
    base = Path(project_dir).resolve()
    target_dir = base / folder
    copies: dict[Path, Path] = {}  # original (resolved) -> copy
    taken: set[str] = set()
    new_assets: dict[str, Asset] = {}
    copied: list[tuple[str, str]] = []
    for ref in file_refs(doc.assets.values()):
        original = Path(ref.path).resolve()
        if is_inside(original, base) or not original.exists():
            continue  # already travels with the project; a missing file cannot be copied
        copy = copies.get(original)
        if copy is None:
            copy = _free_name(target_dir, original, taken)
            taken.add(copy.name)
            if not _same_content(original, copy):
                _copy(original, copy)
                copied.append((str(original), str(copy)))
            copies[original] = copy
        current = new_assets.get(ref.asset_id, doc.assets[ref.asset_id])
        new_assets[ref.asset_id] = with_path(current, ref.key, str(copy))
    command = SetAssetFiles(doc, new_assets) if new_assets else None
    return CollectResult(command, copied)


def _free_name(target_dir: Path, original: Path, taken: set[str]) -> Path:
    """``target_dir/original.name``, or ``stem-2.suffix``… when another file holds the name."""
    stem, suffix = (original.name, "") if original.is_dir() else (original.stem, original.suffix)
    k = 1
    while True:
        name = f"{stem}{suffix}" if k == 1 else f"{stem}-{k}{suffix}"
        candidate = target_dir / name
        if name not in taken and (not candidate.exists() or _same_content(original, candidate)):
            return candidate
        k += 1


def _same_content(a: Path, b: Path) -> bool:
    if not b.exists():
        return False
    if a.is_dir() or b.is_dir():
        return False  # folders are copied again (cheap: a few SVG files)
    try:
        return a.stat().st_size == b.stat().st_size and a.read_bytes() == b.read_bytes()
    except OSError:
        return False


def _copy(original: Path, copy: Path) -> None:
    copy.parent.mkdir(parents=True, exist_ok=True)
    if original.is_dir():
        shutil.copytree(original, copy, dirs_exist_ok=True,
                        ignore=shutil.ignore_patterns("__pycache__", ".*"))
        return
    shutil.copy2(original, copy)
    if original.suffix.lower() == ".gltf":
        for rel in gltf_external_files(original):
            src = (original.parent / rel).resolve()
            if src.is_file() and is_inside(src, original.parent):
                dest = copy.parent / rel
                dest.parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(src, dest)


def gltf_external_files(path: Path) -> list[str]:
    """The relative buffer and image URIs of a ``.gltf`` (no ``data:`` or absolute ones)."""
    try:
        obj = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []
    uris: list[str] = []
    for group in ("buffers", "images"):
        items = obj.get(group) if isinstance(obj, dict) else None
        for item in items if isinstance(items, list) else []:
            uri = item.get("uri") if isinstance(item, dict) else None
            if isinstance(uri, str) and uri and ":" not in uri and not uri.startswith(("/", "\\")):
                uris.append(unquote(uri))
    return uris


# ------------------------------------------------------------------ relink
def missing_refs(assets: Iterable[Any]) -> list[FileRef]:
    """The file references whose file (or folder) does not exist."""
    return [ref for ref in file_refs(assets) if not Path(ref.path).exists()]


def find_beside(name: str, folders: Iterable[str | os.PathLike[str]]) -> Path | None:
    """A file or folder called ``name`` in one of ``folders`` or below (breadth first, so
    ``assets/`` comes before deeper folders; at most :data:`SEARCH_DEPTH` levels and
    :data:`SEARCH_LIMIT` entries per folder)."""
    for folder in folders:
        root = Path(folder)
        if not root.is_dir():
            continue
        for candidate in _walk(root):
            if candidate.name == name:
                return candidate.resolve()
    return None


def _walk(root: Path) -> Iterator[Path]:
    """Entries under ``root`` level by level; hidden folders and caches are skipped."""
    seen = 0
    level = [root]
    for _depth in range(SEARCH_DEPTH):
        below: list[Path] = []
        for folder in level:
            try:
                entries = sorted(folder.iterdir())
            except OSError:
                continue
            for entry in entries:
                seen += 1
                if seen > SEARCH_LIMIT:
                    return
                yield entry
                if entry.is_dir() and not entry.is_symlink() and not entry.name.startswith(".") \
                        and entry.name != "__pycache__":
                    below.append(entry)
        level = below
        if not level:
            return
