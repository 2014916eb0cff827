"""No usable OpenGL 3.3 context: the 3D view shows a message, never a crash or a dialog
(issue 30, "No GL, no crash").

The whole program runs in a child process (``nogl_child.py``) where a crash would be a
segfault: Qt's offscreen platform (no OpenGL at all) and Mesa told to offer OpenGL 2.1 on
the private Xvfb. In this process: a failed probe, a surface whose shaders fail, a paint
that raises and a context lost later, each checked on the real widgets.
"""

from __future__ import annotations

import json
import logging
import os
import subprocess
import sys
from pathlib import Path

import gltf_gen
import numpy as np
import pytest
from PIL import Image
from PySide6.QtWidgets import QWidget
from samples import BLENDER_BVH

from qtanimator.render.gl import capability
from qtanimator.render.gl.capability import GLSupport, GLUnavailableError
from qtanimator.ui import view3d as view3d_module
from qtanimator.ui.main_window import MainWindow
from qtanimator.ui.view3d import Viewport3D, grab_with_3d

CHILD = Path(__file__).with_name("nogl_child.py")
REPO = Path(__file__).resolve().parents[2]
#: What the message must say wherever it is shown.
NEEDED = "OpenGL 3.3"
STILL_WORKS = ("2D editor", "curve editor", "dope sheet", "qtanimator render --view 2d")


def _files(folder: Path) -> list[str]:
    bvh = folder / "walker.bvh"
    bvh.write_text(BLENDER_BVH, encoding="utf-8")
    return [str(bvh), str(gltf_gen.three_animations(folder))]


def _run_child(tmp_path: Path, env_changes: dict[str, str | None]) -> tuple[subprocess.CompletedProcess[str],
                                                                            dict]:
    env = dict(os.environ)
    env.update({"XDG_STATE_HOME": str(tmp_path / "state"), "QTANIMATOR_SETTINGS_DIR": str(tmp_path / "settings"),
                "PYTHONPATH": os.pathsep.join([str(REPO), str(REPO / "tests")])})
    for name, value in env_changes.items():
        if value is None:
            env.pop(name, None)
        else:
            env[name] = value
    out = tmp_path / "out"
    out.mkdir()
    proc = subprocess.run([sys.executable, str(CHILD), str(out), *_files(tmp_path)], env=env, cwd=str(tmp_path),
                          capture_output=True, text=True, timeout=240)
    lines = [line for line in proc.stdout.splitlines() if line.startswith("NOGL-RESULT ")]
    result = json.loads(lines[-1].removeprefix("NOGL-RESULT ")) if lines else {}
    return proc, result


def _check_window(proc: subprocess.CompletedProcess[str], result: dict, tmp_path: Path) -> str:
    assert proc.returncode == 0, f"exit {proc.returncode}\n{proc.stderr[-4000:]}"
    assert result, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert not result["has_surface"]
    assert result["message_visible"]
    text = result["message_text"]
    for words in (NEEDED, *STILL_WORKS):
        assert words in text
    assert result["error_dialogs"] == []
    assert "Traceback" not in proc.stderr and "ShaderError" not in proc.stderr
    # The files open: the document has them; the outliner, curve editor and dope sheet show them.
    assert result["opened"] == [True, True]
    assert result["assets"] == ["three_animations", "walker"]
    assert {"walker", "three_animations"} <= set(result["outliner"])
    assert result["curve_channels"] > 0 and result["dope_rows"] > 0
    # Logged once, however often the view was asked to draw.
    assert result["log"].count("3D view disabled") == 1, result["log"]
    _assert_readable(tmp_path / "out" / "message.png")
    return text


def _assert_readable(png: Path) -> None:
    """The grabbed tab is not blank: dark text on a light panel in its middle."""
    rgb = np.asarray(Image.open(png).convert("RGB")).astype(int)
    h, w = rgb.shape[:2]
    middle = rgb[h // 4: 3 * h // 4, w // 8: 7 * w // 8]
    dark = (middle.max(axis=2) < 100).mean()
    assert 0.002 < dark < 0.2, f"{dark:.4f} of the middle is text"


def test_offscreen_platform_shows_the_message_and_opens_3d_files(tmp_path):
    proc, result = _run_child(tmp_path, {"QT_QPA_PLATFORM": "offscreen", "DISPLAY": None, "WAYLAND_DISPLAY": None})
    text = _check_window(proc, result, tmp_path)
    assert result["platform"] == "offscreen" and not result["probe_ok"]
    assert "'offscreen'" in text and "display" in text


@pytest.mark.gl
def test_an_opengl_2_1_driver_shows_the_message(tmp_path):
    proc, result = _run_child(tmp_path, {"QT_QPA_PLATFORM": "xcb", "MESA_GL_VERSION_OVERRIDE": "2.1",
                                         "MESA_GLSL_VERSION_OVERRIDE": "120"})
    if result.get("probe_ok"):
        pytest.skip(f"Mesa ignores MESA_GL_VERSION_OVERRIDE=2.1 here (it gave {result['found']})")
    text = _check_window(proc, result, tmp_path)
    assert result["gl_problem"] == "OpenGL 2.1 < 3.3"
    assert "OpenGL 2.1" in text and "MESA_GL_VERSION_OVERRIDE=2.1" in text


# ------------------------------------------------------------------ in this process
@pytest.fixture
def no_gl(monkeypatch):
    """The probe finds OpenGL 2.1 (as Mesa with the override does)."""
    support = GLSupport("OpenGL 2.1 < 3.3", "2.1 Mesa 22.3.6", "llvmpipe (LLVM 15.0.6, 256 bits)")
    monkeypatch.setattr(view3d_module, "probe_gl", lambda: support)
    monkeypatch.setattr(capability, "_logged", set())
    return support


def test_without_gl_the_view_has_no_surface_and_says_why(qtbot, no_gl, tmp_path, caplog):
    from qtanimator.ui import viewport

    window = MainWindow(install_editors=False)
    viewport.install(window)
    qtbot.addWidget(window)
    window.resize(760, 560)
    window.show()
    qtbot.waitExposed(window)
    view = window.viewport3d
    qtbot.waitUntil(lambda: view.message is not None and view.message.isVisible())
    assert view.gl is None and view.gl_problem == "OpenGL 2.1 < 3.3"
    assert view.findChild(QWidget, "viewport3dSurface") is None
    text = view.message.text()
    assert "This system gave OpenGL 2.1 Mesa 22.3.6 on llvmpipe" in text and NEEDED in text
    for words in STILL_WORKS:
        assert words in text
    # Nothing draws, nothing raises: asking for pictures and frames is harmless.
    view.update()
    window.ctx.set_frame(5)
    assert view.prepare_gl() is False
    with pytest.raises(GLUnavailableError, match="2.1 < 3.3"):
        view.render_image()
    view.frame_selection()
    # The screenshot shows the message (grab_with_3d leaves it as the widgets drew it).
    pixmap = grab_with_3d(window)
    png = tmp_path / "nogl_message.png"
    assert pixmap.save(str(png))
    _assert_readable(png)
    # A second view (another window) does not log it again.
    assert any("3D view disabled" in r.getMessage() for r in caplog.records)
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="qtanimator.gl"):
        other = Viewport3D(window.ctx)
        qtbot.addWidget(other)
    assert other.message is not None and not any("3D view disabled" in r.getMessage() for r in caplog.records)


def test_log_unavailable_logs_each_problem_once(monkeypatch, caplog):
    monkeypatch.setattr(capability, "_logged", set())
    with caplog.at_level(logging.WARNING, logger="qtanimator.gl"):
        assert capability.log_unavailable("OpenGL 2.1 < 3.3", "OpenGL 2.1 Mesa")
        assert not capability.log_unavailable("OpenGL 2.1 < 3.3", "OpenGL 2.1 Mesa")
    assert [r.getMessage() for r in caplog.records] == [
        "3D view disabled: needs OpenGL 3.3 (core profile); found OpenGL 2.1 Mesa: OpenGL 2.1 < 3.3"]


def test_the_message_names_what_was_found_and_what_to_do(monkeypatch):
    monkeypatch.delenv("MESA_GL_VERSION_OVERRIDE", raising=False)
    monkeypatch.delenv("MESA_GLSL_VERSION_OVERRIDE", raising=False)
    offscreen = capability.unavailable_text("no OpenGL context can be made on the Qt platform 'offscreen'")
    assert "needs OpenGL 3.3 (core profile), and none could be had here" in offscreen
    assert "Start qtanimator on a display" in offscreen
    old = capability.unavailable_text("OpenGL 2.1 < 3.3", "OpenGL 2.1 on Some GPU")
    assert "This system gave OpenGL 2.1 on Some GPU (OpenGL 2.1 < 3.3)" in old and "graphics driver" in old
    monkeypatch.setenv("MESA_GL_VERSION_OVERRIDE", "2.1")
    assert "The environment sets MESA_GL_VERSION_OVERRIDE=2.1: unset it" in capability.unavailable_text(
        "OpenGL 2.1 < 3.3", "OpenGL 2.1 Mesa")


# ------------------------------------------------------------- a real GL surface
@pytest.fixture
def gl_window(qtbot):
    from qtanimator.ui import viewport

    def build() -> MainWindow:
        window = MainWindow(install_editors=False)
        viewport.install(window)
        qtbot.addWidget(window)
        window.resize(420, 360)
        window.show()
        qtbot.waitExposed(window)
        return window

    return build


def _drawn(qtbot, window: MainWindow) -> Viewport3D:
    """The 3D view of ``window`` once it has drawn a picture in its own context."""
    view = window.viewport3d
    window.central_tabs.setCurrentWidget(window.viewport_panel)
    qtbot.waitUntil(lambda: view.last_frame_ms > 0 and view.gl.context() is not None)
    return view


def _shows_message(view: Viewport3D) -> bool:
    return view.message is not None and view.message.isVisible() and not view.surface_widget.isVisible()


@pytest.mark.gl
def test_a_context_lost_later_shows_the_message(gl_window, qtbot, monkeypatch):
    monkeypatch.setattr(capability, "_logged", set())
    view = _drawn(qtbot, gl_window())
    context = view.gl.context()
    assert context is not None and context.isValid()
    context.aboutToBeDestroyed.emit()   # as Qt does when the context goes
    qtbot.waitUntil(lambda: _shows_message(view))
    assert view.gl_problem == "the OpenGL context was lost"
    assert "The 3D view stopped drawing: the OpenGL context was lost" in view.message.text()
    view.update()
    view.ctx.set_frame(3)
    qtbot.wait(100)
    with pytest.raises(GLUnavailableError):
        view.render_image()


@pytest.mark.gl
def test_a_paint_without_a_current_context_shows_the_message(gl_window, qtbot, monkeypatch):
    """A lost context cannot be made current: Qt still calls paintGL ("Failed to make context
    current"), which then must not draw through it."""
    monkeypatch.setattr(capability, "_logged", set())
    view = _drawn(qtbot, gl_window())
    view.gl.doneCurrent()
    view.paint_gl()
    qtbot.waitUntil(lambda: _shows_message(view))
    assert view.gl_problem == "the OpenGL context was lost"
    view.update()
    qtbot.wait(100)


@pytest.mark.gl
def test_shaders_that_fail_in_the_surface_show_the_message(gl_window, qtbot, monkeypatch):
    from qtanimator.render.gl.program import ShaderError
    from qtanimator.render.gl.renderer import SceneRenderer

    def fail(_self):
        raise ShaderError("mesh.vert+mesh.frag: error: vertex shader lacks `main'")

    monkeypatch.setattr(SceneRenderer, "initialize", fail)
    monkeypatch.setattr(capability, "_logged", set())
    window = gl_window()
    view = window.viewport3d
    window.central_tabs.setCurrentWidget(window.viewport_panel)
    qtbot.waitUntil(lambda: _shows_message(view))
    assert "ShaderError" in view.gl_problem and "lacks `main'" in view.message.text()


@pytest.mark.gl
def test_a_paint_that_raises_shows_the_message_once(gl_window, qtbot, monkeypatch, caplog):
    monkeypatch.setattr(capability, "_logged", set())
    view = _drawn(qtbot, gl_window())

    def broken(*_args):
        raise RuntimeError("a bug while drawing")

    monkeypatch.setattr(view, "_draw", broken)
    with caplog.at_level(logging.WARNING):
        for frame in range(5):
            view.ctx.set_frame(frame)
            qtbot.wait(20)
        qtbot.waitUntil(lambda: _shows_message(view))
    assert "RuntimeError: a bug while drawing" in view.gl_problem
    # The traceback once, and the reason once.
    assert sum(r.levelno == logging.ERROR and "drawing failed" in r.getMessage() for r in caplog.records) == 1
    assert "stopped drawing: drawing failed (RuntimeError: a bug while drawing)" in view.message.text()
    assert sum("3D view disabled" in r.getMessage() for r in caplog.records) == 1
