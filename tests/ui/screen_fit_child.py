"""Run by ``test_window_fits_the_screen.py`` in its own process: start an Xvfb of the size
given (``1366x768x24``), build the real main window with every editor as the program does on
a first run, open the demo, and print what fits as JSON (logical pixels). ``QT_SCALE_FACTOR``
comes from the environment. A second argument saves a screenshot there."""

from __future__ import annotations

import json
import os
import sys
import tempfile
import time

from qtanimator.render.xvfb import start_private_xvfb


def _rect(r) -> list[int]:  # type: ignore[no-untyped-def]
    return [r.x(), r.y(), r.width(), r.height()]


def main() -> None:
    os.environ["DISPLAY"] = start_private_xvfb(sys.argv[1])
    os.environ["QT_QPA_PLATFORM"] = "xcb"
    os.environ["QTANIMATOR_SETTINGS_DIR"] = tempfile.mkdtemp(prefix="qtanimator-fit-")  # a first run
    from PySide6.QtWidgets import QApplication, QWidget

    from qtanimator.paths import demo_project
    from qtanimator.ui.main_window import MainWindow

    app = QApplication(sys.argv[:1])
    window = MainWindow()
    window.show()
    window.open_path(demo_project())
    end = time.monotonic() + 1.5
    while time.monotonic() < end:
        app.processEvents()
    plot = window.findChild(QWidget, "curvePlot")
    screen = window.screen()
    out = {
        "frame": _rect(window.frameGeometry()),
        "minimum": [window.minimumSizeHint().width(), window.minimumSizeHint().height()],
        "available": _rect(screen.availableGeometry()),
        "device_pixel_ratio": window.devicePixelRatio(),
        "curve_plot": _rect(plot.geometry()) if plot is not None else None,
        "curve_plot_visible": bool(plot is not None and plot.isVisible()),
    }
    if len(sys.argv) > 2:
        window.grab().save(sys.argv[2])
    print("FIT " + json.dumps(out), flush=True)
    window.close()


if __name__ == "__main__":
    main()
