"""The Export dialog says at what rate a GIF is written (at most 50 fps, whole centiseconds)."""

from __future__ import annotations

from qtanimator.document import Document
from qtanimator.ui.export_dialog import ExportDialog, ExportSettings


def test_the_dialog_says_the_gif_rate(qtbot) -> None:  # type: ignore[no-untyped-def]
    dialog = ExportDialog(Document(), None, ExportSettings(out="/tmp/x", fmt="png", fps=60))
    qtbot.addWidget(dialog)
    assert dialog.gif_note.isHidden()  # PNG frames keep every frame
    dialog.format_box.setCurrentIndex(list(dialog.format_box.itemData(i) for i in range(3)).index("gif"))
    assert not dialog.gif_note.isHidden() and "50 fps" in dialog.gif_note.text()
    assert "dropping frames evenly" in dialog.gif_note.text()
    dialog.fps_box.setValue(25)
    assert dialog.gif_note.isHidden()
    dialog.fps_box.setValue(30)
    assert "3 and 4 cs" in dialog.gif_note.text()
