"""Any file name the filesystem allows is saved (issue 31, part 5): an asset whose name is
not UTF-8 (``pip\\xe9.svg`` as bytes, legal on Linux) saves, autosaves and reopens from the
exact bytes; the project file stays UTF-8 JSON, the name stored with an escape."""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import pytest
from samples import PLAIN_DRAWING

from qtanimator.document import Document, UndoStack, open_document, save_document
from qtanimator.document.background_save import BackgroundSaver
from qtanimator.document.character2d import add_characters_command, character
from qtanimator.document.io import to_project_data
from qtanimator.formats.project import load_project

NAME = b"pip\xe9.svg"


def non_utf8_svg(folder: Path) -> str:
    """``folder/pip\\xe9.svg`` created from the bytes; the str Python gives for it."""
    raw = os.path.join(os.fsencode(folder), NAME)
    try:
        fd = os.open(raw, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
    except OSError as exc:  # a filesystem that wants UTF-8 names (macOS)
        pytest.skip(f"the filesystem refuses a name that is not UTF-8: {exc}")
    try:
        os.write(fd, PLAIN_DRAWING.encode("utf-8"))
    finally:
        os.close(fd)
    name = os.fsdecode(raw)
    assert "\udce9" in name  # surrogate-escaped, which UTF-8 cannot store
    return name


def make(folder: Path) -> tuple[Document, str]:
    path = non_utf8_svg(folder)
    doc = Document()
    UndoStack(doc).push(add_characters_command(doc, path))
    return doc, path


pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="Windows names are UTF-16")


def test_a_project_naming_a_non_utf8_file_saves_and_reopens_from_the_exact_bytes(tmp_path: Path) -> None:
    doc, path = make(tmp_path)
    project = tmp_path / "p.qtanim"
    save_document(doc, project)
    raw = project.read_bytes()
    text = raw.decode("utf-8")  # still UTF-8 text
    assert "\\udce9" in text and "\udce9" not in text
    record = json.loads(text)["assets"][0]
    assert os.fsencode(record["source"]) == NAME  # relative to the project, the bytes kept
    again = open_document(project)
    (aid,) = again.assets
    source = again.assets[aid].source
    assert source is not None and os.fsencode(source) == os.path.join(os.fsencode(tmp_path.resolve()), NAME)
    assert [j.name for j in character(again, aid).joints] == [j.name for j in character(doc, aid).joints]
    assert set(again.channels) == set(doc.channels)
    save_document(again, project)
    assert project.read_bytes() == raw  # save, load, save: the same bytes


def test_an_autosave_of_such_a_document_writes_its_recovery_file(tmp_path: Path) -> None:
    doc, path = make(tmp_path)
    recovery = tmp_path / "recovery" / "12345.qtanim"
    recovery.parent.mkdir()
    saver = BackgroundSaver()
    try:
        job = saver.submit(to_project_data(doc), recovery, [(recovery.with_suffix(".json"), b"{}")])
        assert job.wait(30)
        assert job.written and job.error is None
    finally:
        saver.shutdown()
    data = load_project(recovery)
    assert data.assets[0].source is not None and os.fsencode(data.assets[0].source) == os.fsencode(path)
