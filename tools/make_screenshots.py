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
* ``viewport_shadow`` — the 3D tab with the floor shadow, the axes (X) and View ▸ 3D Camera…;
* ``joint_tree`` — the Joints dock with the 3D arm's elbow selected and its DOF sliders;
* ``pendulum_properties`` — the Properties dock for Pip's pendulum lantern;
* ``cloth_panel`` — the Cloth dock with the flag;
* ``cape`` — the 3D tab on Walker walking in its cape (a cloth attached to its chest);
* ``export_dialog`` — File ▸ Export Animation…;
* ``gltf_clips`` — a glTF character with three clips (built here with ``tests/gltf_gen.py``'s
  builder: no such file is in the shared samples), its clip picked in Properties and the
  3D view's clip list open.
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
SHOTS = ("main_window", "curve_editor", "viewport_3d", "viewport_shadow", "joint_tree", "outliner",
         "pendulum_properties", "cloth_panel", "cape", "export_dialog", "gltf_clips")


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

    def cape(self) -> None:
        """The 3D tab at frame 150 framed on Walker, its cape trailing, the Cloth dock in front."""
        self.tab("3D")
        self.ctx.set_frame(150.0)
        dock(self.window, "clothDock").raise_()
        self.window.cloth_panel.asset.setCurrentText("cape")
        view = self.window.viewport3d
        self.ctx.select("walker", "")
        view.frame_selection()
        view.camera.orbit(-55.0, 8.0)
        view.camera.zoom(1.15)
        self.ctx.select("", "")
        view.update()
        settle(self.app, 1.0)
        self.grab_window("cape")

    def viewport_shadow(self) -> None:
        """The 3D tab with the Shadow box ticked (a real click), the axes shown with a real X
        key press, and the camera fields open over the view's corner; the screen is grabbed so
        that the camera window is in the picture."""
        from PySide6.QtCore import QPoint, Qt
        from PySide6.QtGui import QAction
        from PySide6.QtTest import QTest

        self.tab("3D")
        self.ctx.set_frame(90.0)
        self.ctx.select("", "")
        panel = self.window.viewport_panel
        view = panel.view
        view.frame_selection()
        view.set_camera(distance=view.camera.distance * 0.95, azimuth=12.0, inclination=32.0)
        if not panel.shadow.isChecked():
            QTest.mouseClick(panel.shadow, Qt.MouseButton.LeftButton)
        view.setFocus()
        QTest.keyClick(view, Qt.Key.Key_X)
        self.window.findChild(QAction, "actionCamera3d").trigger()
        dialog = self.window.camera_dialog
        settle(self.app, 0.3)
        corner = view.mapToGlobal(QPoint(view.width() - dialog.frameGeometry().width() - 8, 8))
        dialog.move(corner)
        self._settle_and_grab(panel)   # the cloth simulated, the view repainted
        settle(self.app, 0.6)
        origin = panel.mapToGlobal(QPoint(0, 0))
        shot = self.window.screen().grabWindow(0, origin.x(), origin.y(), panel.width(), panel.height())
        dialog.close()
        QTest.keyClick(view, Qt.Key.Key_X)
        QTest.mouseClick(panel.shadow, Qt.MouseButton.LeftButton)
        save_png(shot, self.out / "viewport_shadow.png")

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

    def outliner(self) -> None:
        """The outliner with a cloth added, one asset locked and the fill light off (undone after)."""
        from qtanimator.document import outliner
        from qtanimator.document.cloth import add_cloth_command

        doc = self.ctx.doc
        steps = self.ctx.undo_stack.count()
        if not any(a.kind == "cloth" for a in doc.assets.values()):
            self.ctx.push(add_cloth_command(doc))
        first = next(iter(doc.assets))
        self.ctx.push(outliner.set_flag_command(doc, first, outliner.LOCKED, True))
        self.ctx.push(outliner.set_flag_command(doc, "light2", outliner.HIDDEN, True))
        self.ctx.select("arm", "")
        d = dock(self.window, "jointTreeDock")
        d.setFloating(True)
        d.resize(380, 460)
        tree = self.window.joint_tree.tree
        for i in range(tree.topLevelItemCount()):
            tree.topLevelItem(i).setExpanded(False)
        tree.follow_selection()
        self.grab_widget(d, "outliner")
        d.setFloating(False)
        layout_for_2d(self.window)
        while self.ctx.undo_stack.count() > steps:
            self.ctx.undo_stack.undo()

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


    # -------------------------------------------------------------- glTF clips
    def gltf_clips(self) -> None:
        """A glTF character with three clips: "wave" picked in Properties (a real click on the
        combo's list), then the 3D view's clip list opened on "walk"; the screen is grabbed so
        that the open list is in the picture."""
        from PySide6.QtCore import QPoint, Qt
        from PySide6.QtTest import QTest
        from PySide6.QtWidgets import QApplication, QComboBox

        folder = Path(tempfile.mkdtemp(prefix="qtanimator-clips-"))
        try:
            path = clips_character(folder)
            self.window.ctx.undo_stack.setClean()
            self.window.new_document()
            if not self.window.open_path(path):
                sys.exit("make_screenshots: the clips character did not open")
        finally:
            shutil.rmtree(folder, ignore_errors=True)
        aid = self.ctx.selection[0]
        self.tab("3D")
        props = dock(self.window, "propertiesDock")
        props.raise_()
        settle(self.app, 0.5)

        def choose(combo: QComboBox, text: str) -> None:
            QTest.mouseClick(combo, Qt.MouseButton.LeftButton)
            settle(self.app, QApplication.doubleClickInterval() / 1000 + 0.2)
            view = combo.view()
            rect = view.visualRect(view.model().index(combo.findText(text), 0))
            QTest.mouseMove(view.viewport(), rect.center())
            QTest.mouseClick(view.viewport(), Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier,
                             rect.center())
            settle(self.app, 0.4)

        panel = self.window.properties_panel
        choose(panel.findChild(QComboBox, "characterClip"), "wave (1.5 s)")
        self.ctx.set_frame(36.0)
        self.ctx.select(aid, "forearm_r")
        view = self.window.viewport3d
        view.frame_all()
        view.camera.azimuth, view.camera.inclination = 20.0, 10.0
        view.camera.zoom(0.9)
        view.update()
        settle(self.app, 0.8)
        bar = self.window.viewport_panel.findChild(QComboBox, "viewportClip")
        QTest.mouseClick(bar, Qt.MouseButton.LeftButton)
        settle(self.app, 0.6)
        bar.view().setCurrentIndex(bar.view().model().index(bar.findText("walk (1 s)"), 0))
        settle(self.app, 0.3)
        origin = self.window.mapToGlobal(QPoint(0, 0))
        shot = self.window.screen().grabWindow(0, origin.x(), origin.y(), self.window.width(),
                                               self.window.height())
        bar.hidePopup()
        save_png(shot, self.out / "gltf_clips.png")


def clips_character(folder: Path) -> Path:
    """``clips.glb``: a small skinned figure of coloured parts (shirt, sleeves, trousers, skin,
    shoes) with three animations of different lengths: "idle" (2 s), "wave" (1.5 s) and a
    looping "walk" (1 s). Built with the glTF builder of ``tests/gltf_gen.py``."""
    import numpy as np

    sys.path.insert(0, str(REPO / "tests"))
    try:
        from gltf_gen import Builder, column, merge, quat
    finally:
        sys.path.remove(str(REPO / "tests"))

    b = Builder("clips")
    pelvis = b.node("pelvis", translation=[0.0, 1.0, 0.0])
    chest = b.node("chest", pelvis, translation=[0.0, 0.4, 0.0])
    head = b.node("head", chest, translation=[0.0, 0.35, 0.0])
    joints = [pelvis, chest, head]
    limbs = {}
    for side, sx in (("l", 1.0), ("r", -1.0)):
        arm = b.node(f"arm_{side}", chest, translation=[0.3 * sx, 0.25, 0.0])
        forearm = b.node(f"forearm_{side}", arm, translation=[0.0, -0.32, 0.0])
        leg = b.node(f"leg_{side}", pelvis, translation=[0.13 * sx, -0.05, 0.0])
        knee = b.node(f"knee_{side}", leg, translation=[0.0, -0.45, 0.0])
        limbs[side] = (arm, forearm, leg, knee)
        joints += [arm, forearm, leg, knee]
    at = {j: b.rest_global(j)[:3, 3] for j in joints}
    # Each vertex follows the bone it lies on: a joint's anchor is the middle of its bone.
    down = np.array([0.0, -0.3, 0.0])
    ends = {pelvis: at[pelvis] + [0, -0.05, 0], chest: at[chest] + [0, 0.15, 0], head: at[head] + [0, 0.18, 0]}
    for arm, forearm, leg, knee in limbs.values():
        ends.update({arm: (at[arm] + at[forearm]) / 2, forearm: at[forearm] + down / 2,
                     leg: (at[leg] + at[knee]) / 2, knee: at[knee] + [0, -0.22, 0]})
    anchors = np.array([ends[j] for j in joints])
    shirt = b.material("shirt", [0.08, 0.25, 0.75, 1.0])
    sleeves = b.material("sleeves", [0.05, 0.15, 0.5, 1.0])
    skin_tone = b.material("skin", [0.85, 0.55, 0.4, 1.0])
    trousers = b.material("trousers", [0.25, 0.22, 0.2, 1.0])
    shoes = b.material("shoes", [0.6, 0.08, 0.05, 1.0])
    def part(geometry: tuple[np.ndarray, np.ndarray], material: int, bones: list[int],
             influences: int = 2) -> dict[str, object]:
        """A primitive weighted to the nearest of ``bones`` only (a sleeve never pulls the shirt)."""
        ids = [joints.index(j) for j in bones]
        return b.primitive(*geometry, material=material, anchors=anchors[ids], influences=influences, joint_ids=ids)

    torso = column(at[pelvis] + [0, -0.12, 0], at[chest] + [0, 0.3, 0], 0.46, rings=6, depth=0.26)
    neck_head = column(at[head] - [0, 0.05, 0], at[head] + [0, 0.3, 0], 0.24, rings=4)
    sleeves_geo, hands_geo, legs_geo, shoes_geo = [], [], [], []
    for arm, forearm, leg, knee in limbs.values():
        sleeves_geo.append(column(at[arm] + [0, 0.05, 0], at[forearm] + down * 0.9, 0.12, rings=7))
        hands_geo.append(column(at[forearm] + down * 0.8, at[forearm] + down * 1.3, 0.13, rings=2))
        legs_geo.append(column(at[leg] + [0, 0.08, 0], at[knee] + [0, -0.42, 0], 0.17, rings=7))
        shoes_geo.append(column(at[knee] + [0, -0.42, -0.05], at[knee] + [0, -0.42, 0.2], 0.14, rings=2,
                                depth=0.08))
    arms = [j for side in limbs.values() for j in side[:2]]
    legs = [j for side in limbs.values() for j in side[2:]]
    forearms = [limbs["l"][1], limbs["r"][1]]
    figure = b.mesh([part(torso, shirt, [pelvis, chest]), part(merge(*sleeves_geo), sleeves, arms),
                     part(neck_head, skin_tone, [head]), part(merge(*hands_geo), skin_tone, forearms, 1),
                     part(merge(*legs_geo), trousers, legs), part(merge(*shoes_geo), shoes, legs)], "figure")
    b.node("figure", mesh=figure, skin=0)
    b.skin(joints, skeleton=pelvis)

    def turns(axis: list[float], degrees: list[float]) -> np.ndarray:
        return np.array([quat(axis, d) for d in degrees])

    arm_l, forearm_l, leg_l, knee_l = limbs["l"]
    arm_r, forearm_r, leg_r, knee_r = limbs["r"]
    t3 = [0.0, 1.0, 2.0]
    b.animation("idle", [
        (chest, "rotation", t3, turns([0, 0, 1], [-3, 3, -3]), "LINEAR"),
        (head, "rotation", t3, turns([1, 0, 0], [0, 8, 0]), "LINEAR"),
        (arm_l, "rotation", t3, turns([0, 0, 1], [8, 5, 8]), "LINEAR"),
        (arm_r, "rotation", t3, turns([0, 0, 1], [-8, -5, -8]), "LINEAR"),
    ])
    tw = [0.0, 0.3, 0.5, 0.7, 0.9, 1.1, 1.5]
    b.animation("wave", [
        (arm_r, "rotation", tw, turns([0, 0, 1], [-8, -150, -150, -150, -150, -150, -8]), "LINEAR"),
        (forearm_r, "rotation", tw, turns([0, 0, 1], [0, 0, 35, -25, 35, 0, 0]), "LINEAR"),
        (head, "rotation", [0.0, 0.5, 1.5], turns([0, 0, 1], [0, -10, 0]), "LINEAR"),
    ])
    t5 = [0.0, 0.25, 0.5, 0.75, 1.0]
    swing = [25, 0, -25, 0, 25]
    b.animation("walk", [
        (leg_l, "rotation", t5, turns([1, 0, 0], [-s for s in swing]), "LINEAR"),
        (leg_r, "rotation", t5, turns([1, 0, 0], swing), "LINEAR"),
        (knee_l, "rotation", t5, turns([1, 0, 0], [10, 35, 5, 0, 10]), "LINEAR"),
        (knee_r, "rotation", t5, turns([1, 0, 0], [5, 0, 10, 35, 5]), "LINEAR"),
        (arm_l, "rotation", t5, turns([1, 0, 0], [-20, 0, 20, 0, -20]), "LINEAR"),
        (arm_r, "rotation", t5, turns([1, 0, 0], [20, 0, -20, 0, 20]), "LINEAR"),
        (pelvis, "translation", t5, [[0, 1.0, 0], [0, 1.04, 0], [0, 1.0, 0], [0, 1.04, 0], [0, 1.0, 0]], "LINEAR"),
    ])
    return b.save(folder / "clips.glb")


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
        # gltf_clips last: it replaces the demo
        order = ["main_window", "pendulum_properties", "curve_editor", "viewport_3d", "viewport_shadow", "joint_tree",
                 "outliner", "cloth_panel", "cape", "export_dialog", "gltf_clips"]
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
