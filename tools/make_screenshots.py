"""Take the documentation screenshots from the real program.

Run: ``.venv/bin/python tools/make_screenshots.py [--out docs/images] [--only NAME ...]``

It starts a private Xvfb (so Qt runs on ``xcb`` with real Mesa OpenGL, whatever display you
have), opens the bundled demo project (``scenes/demo/demo.qtanim``) in the real
:class:`qtanimator.ui.main_window.MainWindow`, performs real edits with the mouse and the
editors' own APIs (a right-drag IK pose, key selection in the curve editor, a joint picked
in the 3D viewport…), grabs the window or one of its docks, and writes optimised PNGs at
most 1400 pixels wide. Settings and autosaves go to a temporary folder, so your own layout
and recent files are not touched; nothing is saved to the demo project.

Shots (``docs/images/NAME.png``):

* ``main_window`` — the whole window on the 2D rig editor after an IK drag;
* ``curve_editor`` — the curve editor with keys selected and their tangent handles;
* ``viewport_3d`` — the 3D tab: the waving arm, the flag in the wind, the two lights;
* ``joint_tree`` — the Joints dock with the 3D arm's elbow selected and its DOF sliders;
* ``pendulum_properties`` — the Properties dock for Pip's pendulum lantern;
* ``cloth_panel`` — the Cloth dock with the flag;
* ``export_dialog`` — File ▸ Export Animation….
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
OUT = REPO / "docs" / "images"
MAX_WIDTH = 1400
WINDOW_SIZE = (1400, 900)
SHOTS = ("main_window", "curve_editor", "viewport_3d", "joint_tree", "pendulum_properties", "cloth_panel",
         "export_dialog")


# ------------------------------------------------------------------ display
# ------------------------------------------------------------------ helpers
def settle(app, seconds: float = 0.3) -> None:  # type: ignore[no-untyped-def]
    """Let Qt process events (and GL paint) for a while."""
    from PySide6.QtCore import QCoreApplication, QEvent

    end = time.monotonic() + seconds
    while time.monotonic() < end:
        app.processEvents()
        # deleteLater() runs only back in the event loop; this script drives Qt by hand.
        QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)
        time.sleep(0.01)


def save_png(image, path: Path, max_width: int = MAX_WIDTH) -> None:  # type: ignore[no-untyped-def]
    """Save a QImage / QPixmap as an optimised PNG no wider than ``max_width``."""
    from PIL import Image

    tmp = path.with_suffix(".raw.png")
    image.save(str(tmp), "PNG")
    with Image.open(tmp) as im:
        im = im.convert("RGB")
        if im.width > max_width:
            im = im.resize((max_width, round(im.height * max_width / im.width)), Image.Resampling.LANCZOS)
        # A 256-colour palette keeps UI screenshots sharp and small.
        im = im.quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
        im.save(path, optimize=True)
    tmp.unlink()
    print(f"wrote {path.relative_to(REPO) if path.is_relative_to(REPO) else path}")


def dock(window, name: str):  # type: ignore[no-untyped-def]
    from PySide6.QtWidgets import QDockWidget

    d = window.findChild(QDockWidget, name)
    assert d is not None, f"no dock {name}"
    return d


def layout_for_2d(window) -> None:  # type: ignore[no-untyped-def]
    """Joints on the left; Properties, Cloth and Lights tabbed on the right; timeline and a
    taller curve editor at the bottom."""
    from PySide6.QtCore import Qt

    right = [dock(window, n) for n in ("propertiesDock", "clothDock", "lightDock")]
    window.tabifyDockWidget(right[0], right[1])
    window.tabifyDockWidget(right[1], right[2])
    dock(window, "undoHistoryDock").hide()
    for d in right:
        d.show()
    right[0].raise_()
    window.resizeDocks([dock(window, "jointTreeDock")], [250], Qt.Orientation.Horizontal)
    window.resizeDocks([right[0]], [330], Qt.Orientation.Horizontal)
    window.resizeDocks([dock(window, "curveEditorDock")], [260], Qt.Orientation.Vertical)
    window.resizeDocks([dock(window, "timelineDock"), dock(window, "curveEditorDock")], [560, 840],
                       Qt.Orientation.Horizontal)


# ------------------------------------------------------------------ the shots
class Shooter:
    def __init__(self, out: Path) -> None:
        from PySide6.QtWidgets import QApplication

        from qtanimator.paths import demo_project
        from qtanimator.ui.main_window import MainWindow

        self.out = out
        self.app = QApplication.instance() or QApplication(["qtanimator"])
        self.app.setApplicationName("qtanimator")
        self.window = MainWindow()
        self.window.resize(*WINDOW_SIZE)
        self.window.show()
        if not self.window.open_path(demo_project()):
            sys.exit("make_screenshots: the demo project did not open")
        layout_for_2d(self.window)
        settle(self.app, 0.8)

    @property
    def ctx(self):  # type: ignore[no-untyped-def]
        return self.window.ctx

    def tab(self, title: str) -> None:
        tabs = self.window.central_tabs
        for i in range(tabs.count()):
            if tabs.tabText(i) == title:
                tabs.setCurrentIndex(i)
                settle(self.app, 0.3)
                return
        raise KeyError(title)

    def _settle_and_grab(self, widget):  # type: ignore[no-untyped-def]
        """The widget's picture once the cloth is simulated (3D views drawn in)."""
        from qtanimator.document.cloth_worker import cloth_worker
        from qtanimator.ui.viewport import grab_with_3d

        cloth_worker(self.ctx.doc).wait(120)
        self.window.viewport3d.update()
        settle(self.app, 0.5)
        return grab_with_3d(widget)

    def grab_window(self, name: str) -> None:
        save_png(self._settle_and_grab(self.window), self.out / f"{name}.png")

    def grab_widget(self, widget, name: str, max_width: int = MAX_WIDTH) -> None:  # type: ignore[no-untyped-def]
        save_png(self._settle_and_grab(widget), self.out / f"{name}.png", max_width)

    # -------------------------------------------------------------- 2D
    def main_window(self) -> None:
        """The 2D editor after a real right-drag IK on Pip's left hand, at frame 45."""
        from PySide6.QtCore import QPoint, Qt
        from PySide6.QtTest import QTest
        from PySide6.QtWidgets import QWidget

        from qtanimator.document import channel_id
        from qtanimator.document import character2d as c2d

        self.tab("2D Rig")
        self.ctx.set_frame(45.0)
        settle(self.app, 0.3)
        view = self.window.findChild(QWidget, "rigEditorView")
        pip = self.ctx.doc.runtime["pip"]
        hand = pip.joint_index("hand_left")
        pose = c2d.evaluate_pose(self.ctx.doc, "pip", self.ctx.time)
        start = view.from_scene(pose.pivots[hand])
        p0 = QPoint(int(start.x()), int(start.y()))
        vp = view.viewport()
        QTest.mousePress(vp, Qt.MouseButton.RightButton, Qt.KeyboardModifier.NoModifier, p0)
        for i in range(1, 13):
            QTest.mouseMove(vp, p0 + QPoint(-4 * i, -7 * i))
            settle(self.app, 0.02)
        QTest.mouseRelease(vp, Qt.MouseButton.RightButton, Qt.KeyboardModifier.NoModifier,
                           p0 + QPoint(-48, -84))
        self.ctx.select("pip", "forearm_left")
        editor = self._curve_editor()
        arm = [channel_id("pip", j, "angle") for j in ("upper_arm_left", "forearm_left")]
        editor.tree.set_checked(editor.tree.channel_ids(), False)
        editor.tree.set_checked(arm, True)
        settle(self.app, 0.2)
        editor.view.frame_all()
        self.fit_2d()
        self.grab_window("main_window")
        editor.tree.set_checked(editor.tree.channel_ids(), True)

    def fit_2d(self) -> None:
        from PySide6.QtGui import QAction

        fit = self.window.findChild(QAction, "actionFitView")
        assert fit is not None
        settle(self.app, 0.2)
        fit.trigger()

    def curve_editor(self) -> None:
        """Pip's right arm channels with two keys selected: their handles show."""
        from qtanimator.document import channel_id

        cids = [channel_id("pip", "upper_arm_right", "angle"), channel_id("pip", "forearm_right", "angle")]
        self.ctx.select("pip", "upper_arm_right")
        self.ctx.select_channels(cids)
        editor = self._curve_editor()
        editor.tree.set_checked(editor.tree.channel_ids(), False)
        editor.tree.set_checked(cids, True)
        settle(self.app, 0.2)
        editor.view.set_selection({cids[0]: [1, 2], cids[1]: [2]}, (cids[0], 1))
        editor.view.frame_all()
        self.ctx.set_frame(100.0)
        d = dock(self.window, "curveEditorDock")
        d.setFloating(True)
        d.resize(1200, 520)
        settle(self.app, 0.6)
        editor.view.frame_all()
        self.grab_widget(d, "curve_editor")
        d.setFloating(False)
        editor.tree.set_checked(editor.tree.channel_ids(), True)
        layout_for_2d(self.window)
        settle(self.app, 0.3)

    def _curve_editor(self):  # type: ignore[no-untyped-def]
        from PySide6.QtWidgets import QWidget

        w = self.window.findChild(QWidget, "curveEditor")
        assert w is not None
        return w

    def pendulum_properties(self) -> None:
        self.tab("2D Rig")
        self.ctx.select("pip", "lantern")
        d = dock(self.window, "propertiesDock")
        d.raise_()
        d.setFloating(True)
        d.resize(440, 940)
        self.grab_widget(d, "pendulum_properties")
        d.setFloating(False)
        layout_for_2d(self.window)

    # -------------------------------------------------------------- 3D
    def viewport_3d(self) -> None:
        """The 3D tab at frame 90 with the Lights dock in front."""
        from qtanimator.document import character3d

        self.tab("3D")
        self.ctx.set_frame(90.0)
        dock(self.window, "lightDock").raise_()
        view = self.window.viewport3d
        self.ctx.select("", "")
        view.frame_selection()  # everything: the arm, the flag
        view.camera.orbit(-18.0, 2.0)
        view.camera.zoom(1.05)
        # The elbow selected: highlighted in the skeleton, its channels in the curve editor.
        self.ctx.select("arm", "elbow")
        editor = self._curve_editor()
        cids = [c for c in character3d.channel_ids(self.ctx.doc, "arm") if "/elbow/" in c or "/shoulder/" in c]
        editor.tree.set_checked(editor.tree.channel_ids(), False)
        editor.tree.set_checked(cids, True)
        settle(self.app, 0.2)
        editor.view.frame_all()
        view.update()
        settle(self.app, 1.0)
        self.grab_window("viewport_3d")
        editor.tree.set_checked(editor.tree.channel_ids(), True)

    def joint_tree(self) -> None:
        self.tab("3D")
        self.ctx.select("arm", "elbow")
        d = dock(self.window, "jointTreeDock")
        d.setFloating(True)
        d.resize(380, 420)
        tree = self.window.joint_tree.tree
        if hasattr(tree, "collapseAll"):
            tree.collapseAll()
            self.window.joint_tree.tree.follow_selection()
        self.grab_widget(d, "joint_tree")
        d.setFloating(False)
        layout_for_2d(self.window)

    def cloth_panel(self) -> None:
        self.tab("3D")
        d = dock(self.window, "clothDock")
        d.raise_()
        d.setFloating(True)
        d.resize(640, 940)
        self.grab_widget(d, "cloth_panel")
        d.setFloating(False)
        layout_for_2d(self.window)

    # -------------------------------------------------------------- export
    def export_dialog(self) -> None:
        from qtanimator.ui.export_dialog import ExportDialog

        dialog = ExportDialog(self.window.doc, self.window)
        dialog.format_box.setCurrentIndex(dialog.format_box.findData("gif"))
        dialog.path_edit.setText(str(Path.home() / "demo.gif"))
        dialog.resize(560, dialog.sizeHint().height())
        dialog.show()
        settle(self.app, 0.4)
        self.grab_widget(dialog, "export_dialog")
        dialog.reject()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description="Take the documentation screenshots from the real program.")
    ap.add_argument("--out", type=Path, default=OUT, help="output folder (default docs/images)")
    ap.add_argument("--only", nargs="*", choices=SHOTS, help="take only these shots")
    ap.add_argument("--keep-display", action="store_true",
                    help="use $DISPLAY as it is instead of starting a private Xvfb")
    ns = ap.parse_args(argv)
    ns.out.mkdir(parents=True, exist_ok=True)

    if not ns.keep_display:
        from qtanimator.render.xvfb import start_private_xvfb  # stopped when this script exits

        try:
            os.environ["DISPLAY"] = start_private_xvfb("1600x1000x24")
        except OSError as exc:
            sys.exit(f"make_screenshots: {exc}")
    os.environ["QT_QPA_PLATFORM"] = "xcb"
    settings_dir = tempfile.mkdtemp(prefix="qtanimator-shots-")
    os.environ["QTANIMATOR_SETTINGS_DIR"] = settings_dir
    try:
        shooter = Shooter(ns.out)
        order = ["main_window", "pendulum_properties", "curve_editor", "viewport_3d", "joint_tree", "cloth_panel",
                 "export_dialog"]
        for name in order:
            if ns.only and name not in ns.only:
                continue
            shot: Callable[[], None] = getattr(shooter, name)
            shot()
        shooter.window.ctx.undo_stack.setClean()  # nothing to save: the window closes quietly
        shooter.window.close()
        settle(shooter.app, 0.2)
    finally:
        shutil.rmtree(settings_dir, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
