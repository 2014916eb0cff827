"""The real program's window without a usable OpenGL 3.3 context, run in a child process by
``tests/ui/test_view3d_nogl.py`` (a crash there is an exit status, not a dead test run).

``python nogl_child.py OUT_DIR BVH GLTF``: builds the whole MainWindow as ``qtanimator``
does (log file, exception hook), shows it with the "3D" tab current, opens the BVH and the
glTF, lets events run for a while, grabs the 3D tab to ``OUT_DIR/message.png`` and prints
what it saw as one JSON line. The Qt platform and GL come from the environment
(``QT_QPA_PLATFORM=offscreen``, or a display with ``MESA_GL_VERSION_OVERRIDE=2.1``).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path


def run(out: Path, paths: list[str]) -> dict[str, object]:
    from PySide6.QtWidgets import QApplication

    from qtanimator import applog
    from qtanimator.render.gl.capability import probe_gl
    from qtanimator.ui import errors
    from qtanimator.ui.main_window import MainWindow
    from qtanimator.ui.view3d import grab_with_3d

    log_file = applog.setup_logging()
    app = QApplication.instance() or QApplication(["qtanimator"])
    errors.install_excepthook()
    shown: list[str] = []
    # An error dialog would block: record it and go on (the test fails on any).
    errors.ErrorDialog.exec = lambda self: shown.append(self.windowTitle()) or 0  # type: ignore[method-assign]

    def spin(seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            app.processEvents()
            time.sleep(0.01)

    window = MainWindow()
    window.resize(1280, 800)
    window.show()
    panel = window.viewport_panel  # type: ignore[attr-defined]
    window.central_tabs.setCurrentWidget(panel)
    spin(1.0)
    opened = [bool(window.open_path(p)) for p in paths]
    spin(1.0)
    # Back and forth between the tabs, and play a little: nothing may draw into a dead GL.
    window.central_tabs.setCurrentIndex(0)
    spin(0.3)
    window.central_tabs.setCurrentWidget(panel)
    window.ctx.set_frame(10)
    view = window.viewport3d  # type: ignore[attr-defined]
    view.update()
    spin(1.0)
    message = view.message
    grab_with_3d(window).save(str(out / "window.png"))
    panel.grab().save(str(out / "message.png"))
    tree = window.joint_tree.tree  # type: ignore[attr-defined]
    outliner = [tree.topLevelItem(i).text(0) for i in range(tree.topLevelItemCount())]
    support = probe_gl()
    result = {
        "platform": QApplication.platformName(),
        "probe_ok": support.ok,
        "found": support.found,
        "gl_problem": view.gl_problem,
        "has_surface": view.gl is not None,
        "message_visible": bool(message is not None and message.isVisible()),
        "message_text": message.text() if message is not None else "",
        "opened": opened,
        "assets": sorted(window.doc.assets),
        "outliner": outliner,
        "curve_channels": len(window.curve_editor.tree.channel_ids()),  # type: ignore[attr-defined]
        "dope_rows": len(window.dope_sheet.view.rows),  # type: ignore[attr-defined]
        "error_dialogs": shown,
        "log": log_file.read_text(encoding="utf-8") if log_file is not None and log_file.exists() else "",
    }
    window.ctx.undo_stack.setClean()
    window.close()
    spin(0.2)
    return result


def main() -> int:
    out = Path(sys.argv[1])
    result = run(out, sys.argv[2:])
    print("NOGL-RESULT " + json.dumps(result), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
