"""The real program's window opening hostile projects, run in a child process by
``tests/ui/test_hostile_projects_window.py`` (a crash there is an exit status, not a dead
test run; issue 31 found a 349-byte project that segfaulted pyqtgraph's paint).

``python hostile_project_child.py GOOD EDGE HOSTILE...``: builds the whole MainWindow as
``qtanimator`` does (log file, exception hook), opens the project ``GOOD``, then tries every
``HOSTILE`` project, painting the window after each; then opens ``EDGE`` (numbers at the
bounds a project may hold) and frames it in the curve editor and the dope sheet; last, it
puts a channel no project may hold (keys 5e-324 s apart, cycling) straight into a document
and paints again. Prints what it saw as one JSON line. Error dialogs are recorded, not shown.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path
from typing import Any


def run(good: str, edge: str, hostile: list[str]) -> dict[str, Any]:
    from docfix import set_channels
    from PySide6.QtWidgets import QApplication

    from qtanimator import applog
    from qtanimator.core.channel import Channel, Key
    from qtanimator.ui import errors
    from qtanimator.ui.main_window import MainWindow

    log_file = applog.setup_logging()
    app = QApplication.instance() or QApplication(["qtanimator"])
    errors.install_excepthook()
    unexpected: list[str] = []
    # An error dialog would block: record it and go on.
    errors.ErrorDialog.exec = lambda self: unexpected.append(self.windowTitle()) or 0  # type: ignore[method-assign]

    def spin(seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            app.processEvents()
            time.sleep(0.01)

    window = MainWindow()
    shown: list[list[str]] = []
    window.show_error = lambda title, text: shown.append([title, text])  # type: ignore[method-assign]
    window.resize(1280, 800)
    window.show()
    spin(0.5)
    result: dict[str, Any] = {"good_opened": bool(window.open_path(good))}
    spin(0.3)
    good_doc = window.doc
    before = {"path": good_doc.path, "assets": sorted(good_doc.assets), "channels": sorted(good_doc.channels)}
    result["good"] = before
    result["hostile"] = []
    for path in hostile:
        shown.clear()
        opened = bool(window.open_path(path))
        spin(0.2)
        window.grab()  # paint every view now
        result["hostile"].append({
            "file": Path(path).name,
            "opened": opened,
            "dialogs": list(shown),
            "same_document": window.doc is good_doc and window.doc.path == before["path"]
            and sorted(window.doc.assets) == before["assets"] and sorted(window.doc.channels) == before["channels"],
        })
    shown.clear()
    result["edge_opened"] = bool(window.open_path(edge))
    spin(0.3)
    curves = window.curve_editor  # type: ignore[attr-defined]
    sheet = window.dope_sheet.view  # type: ignore[attr-defined]
    curves.view.frame_all()
    sheet.frame_all()
    spin(0.2)
    window.grab()
    result["edge_dialogs"] = list(shown)
    result["edge_curve_range"] = curves.view.vb.viewRange()
    result["edge_sheet"] = [sheet.left_frame, sheet.px_per_frame]
    # A channel no project may hold, put straight into a document: the views must not
    # compute NaN ranges from it nor hand Qt NaN geometry.
    window.open_path(good)
    spin(0.3)
    set_channels(window.doc, {"pencil//x": Channel([Key(0.0, 0.0), Key(5e-324, 1.0)], pre="cycle", post="cycle")})
    curves.tree.select_all() if hasattr(curves.tree, "select_all") else None
    spin(0.3)
    curves.view.frame_all()
    sheet.frame_all()
    window.grab()
    spin(0.2)
    result["raw_curve_range"] = curves.view.vb.viewRange()
    result["raw_shown"] = "pencil//x" in curves.view.visible
    result["raw_sheet"] = [sheet.left_frame, sheet.px_per_frame]
    ranges = [*result["edge_curve_range"], *result["raw_curve_range"]]
    numbers = [v for pair in ranges for v in pair] + [*result["edge_sheet"], *result["raw_sheet"]]
    result["finite"] = all(math.isfinite(v) for v in numbers)
    result["unexpected_dialogs"] = unexpected
    result["log"] = log_file.read_text(encoding="utf-8") if log_file is not None and log_file.exists() else ""
    window.ctx.undo_stack.setClean()
    window.close()
    spin(0.2)
    return result


def main() -> int:
    result = run(sys.argv[1], sys.argv[2], sys.argv[3:])
    print("HOSTILE-RESULT " + json.dumps(result), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
