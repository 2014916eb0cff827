"""The window's autosave writes a recovery file for a document whose asset's file name is
not UTF-8 (issue 31, part 5: before, every autosave failed with UnicodeEncodeError)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
from samples import PLAIN_DRAWING

from qtanimator.document.character2d import add_characters_command
from qtanimator.formats.project import load_project
from qtanimator.ui.main_window import MainWindow


@pytest.mark.skipif(sys.platform == "win32", reason="Windows names are UTF-16")
def test_autosave_of_a_document_naming_a_non_utf8_file(qtbot, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    raw = os.path.join(os.fsencode(tmp_path), b"pip\xe9.svg")
    try:
        fd = os.open(raw, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
    except OSError as exc:
        pytest.skip(f"the filesystem refuses a name that is not UTF-8: {exc}")
    os.write(fd, PLAIN_DRAWING.encode("utf-8"))
    os.close(fd)
    window = MainWindow()
    qtbot.addWidget(window)
    window.ctx.push(add_characters_command(window.doc, os.fsdecode(raw)))
    manager = window.recovery
    assert manager.autosave(wait=True)
    assert manager.project_path.is_file()
    (record,) = load_project(manager.project_path).assets
    assert record.source is not None and os.fsencode(record.source) == raw
    manager.discard()
