"""The main window fits a 1366×768 laptop and a 1080p screen at scale 2 (issue 30, part 5):
on a first run it opens inside the available screen area, its minimum size fits that area,
and the curve editor's plot gets a usable height. Each screen is a private Xvfb of that
size in a child process (``screen_fit_child.py``), with the real window and every editor."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from needs import missing
from PySide6.QtCore import QByteArray, QRect

from qtanimator.ui.app_settings import settings
from qtanimator.ui.main_window import MainWindow

CHILD = Path(__file__).with_name("screen_fit_child.py")


def _measure(screen: str, scale: str | None, shot: Path) -> dict:  # type: ignore[type-arg]
    if shutil.which("Xvfb") is None:
        missing("Xvfb is not installed")
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "QT_SCALE_FACTOR")}
    if scale:
        env["QT_SCALE_FACTOR"] = scale
    done = subprocess.run([sys.executable, str(CHILD), screen, str(shot)], env=env, capture_output=True,
                          text=True, timeout=120)
    lines = [line for line in done.stdout.splitlines() if line.startswith("FIT ")]
    assert done.returncode == 0 and lines, done.stderr[-3000:]
    return json.loads(lines[-1][4:])


def _inside(inner: list[int], outer: list[int]) -> bool:
    return (inner[0] >= outer[0] and inner[1] >= outer[1] and inner[0] + inner[2] <= outer[0] + outer[2]
            and inner[1] + inner[3] <= outer[1] + outer[3])


@pytest.mark.parametrize(("screen", "scale", "available", "plot_height"), [
    ("1366x768x24", None, (1366, 768), 150),
    ("1920x1080x24", "2", (960, 540), 60),
], ids=["laptop-1366x768", "1080p-scale-2"])
def test_the_first_run_window_fits_the_screen(tmp_path, screen, scale, available, plot_height):
    fit = _measure(screen, scale, tmp_path / "window.png")
    assert fit["available"][2:] == list(available), fit
    assert _inside(fit["frame"], fit["available"]), fit
    # The minimum fits too, with room for a desktop panel at scale 1 (1366 × 720).
    room = 48 if scale is None else 0
    assert fit["minimum"][0] <= available[0] and fit["minimum"][1] <= available[1] - room, fit
    assert fit["curve_plot_visible"] and fit["curve_plot"][3] >= plot_height, fit
    assert (tmp_path / "window.png").is_file()


def test_a_restored_window_larger_than_the_screen_is_clamped(qtbot):
    big = MainWindow()
    qtbot.addWidget(big)
    area = big.available_geometry()
    big.setGeometry(QRect(area.x() - 200, area.y() - 100, area.width() + 900, area.height() + 700))
    settings().setValue("window/geometry", big.saveGeometry())
    settings().remove("window/state")
    try:
        restored = MainWindow()
        qtbot.addWidget(restored)
        restored.show()
        qtbot.waitExposed(restored)
        assert area.contains(restored.frameGeometry()), (restored.frameGeometry(), area)
    finally:
        settings().remove("window/geometry")


def test_the_first_run_size_is_a_share_of_the_screen(qtbot):
    settings().remove("window/geometry")
    window = MainWindow()
    qtbot.addWidget(window)
    area = window.available_geometry()
    assert area.contains(window.geometry())
    assert window.width() <= 1600 and window.height() <= 1000
    assert isinstance(window.saveGeometry(), QByteArray)
