"""The command line: help, info, and one-line errors without tracebacks."""

from __future__ import annotations

import builtins
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from qtanimator.cli import main
from qtanimator.core.channel import Key
from qtanimator.document import Document, InsertKey, SetParameter, UndoStack, save_document


@pytest.fixture()
def project(tmp_path: Path) -> Path:
    doc = Document()
    stack = UndoStack(doc)
    stack.push(InsertKey(doc, "hero//x", Key(0.5, 1.0)))
    stack.push(InsertKey(doc, "hero//x", Key(2.0, 3.0)))
    stack.push(InsertKey(doc, "hero/arm/rz", Key(1.0, 0.1)))
    stack.push(SetParameter(doc, "fps", 24))
    path = tmp_path / "scene.qtanim"
    save_document(doc, path)
    return path


def one_line_error(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


def test_help(capsys):
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert "usage: qtanimator" in out and "render" in out and "info" in out
    assert main(["info", "--help"]) == 0
    assert "--json" in capsys.readouterr().out
    assert main(["--version"]) == 0
    assert "qtanimator" in capsys.readouterr().out


def test_info_text_and_json(project, capsys):
    assert main(["info", str(project)]) == 0
    out = capsys.readouterr().out
    assert "kind: qtanimator project" in out and "channels: 2" in out and "keys: 3" in out
    assert main(["info", str(project), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["channels"] == 2 and summary["keys"] == 3
    assert summary["key_time_range"] == [0.5, 2.0]
    assert summary["parameters"]["fps"] == 24


@pytest.mark.parametrize("make_args, words", [
    (lambda p: ["info", str(p.parent / "missing.qtanim")], "no such file"),
    (lambda p: ["info"], "required"),
    (lambda p: ["info", str(p), "--frobnicate"], "unrecognized arguments"),
    (lambda p: ["info", str(p.with_suffix(".xyz"))], "does not read"),
    (lambda p: [str(p.parent / "missing.qtanim")], "no such file"),
])
def test_bad_input_is_one_line_and_non_zero(project, capsys, make_args, words):
    project.with_suffix(".xyz").write_text("?")
    status = main(make_args(project))
    assert status != 0
    assert words in one_line_error(capsys)


def test_a_corrupt_project_is_one_line(project, capsys):
    project.write_text('{"format": "qtanimator-project", "version": 1, "channels": {"x": ')
    assert main(["info", str(project)]) == 1
    line = one_line_error(capsys)
    assert line.startswith("qtanimator: scene.qtanim, line 1") and "not valid JSON" in line


def test_render_missing_is_a_one_line_error(capsys, monkeypatch):
    real_import = builtins.__import__

    def no_render(name, *args, **kwargs):  # type: ignore[no-untyped-def]
        if name == "qtanimator.render.cli_render":
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_render)
    monkeypatch.delitem(sys.modules, "qtanimator.render.cli_render", raising=False)
    assert main(["render", "scene.qtanim", "-o", "out.gif"]) == 1
    assert "rendering is not available" in one_line_error(capsys)


def test_an_unexpected_error_is_one_line_too(project, capsys, monkeypatch):
    import qtanimator.formats.info as info

    def broken(path: Path) -> dict[str, object]:
        raise ZeroDivisionError("boom\nsecond line")

    monkeypatch.setattr(info, "summarize", broken)
    monkeypatch.delenv("QTANIMATOR_DEBUG", raising=False)
    assert main(["info", str(project)]) == 70
    assert "internal error: ZeroDivisionError: boom second line" in one_line_error(capsys)


def test_the_installed_command_runs_in_a_fresh_process(project, tmp_path):
    exe = Path(sys.executable).with_name("qtanimator")
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "qtanimator"]
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen"}
    ok = subprocess.run([*cmd, "info", str(project), "--json"], capture_output=True, text=True, env=env,
                        timeout=60)
    assert ok.returncode == 0 and json.loads(ok.stdout)["keys"] == 3
    bad = tmp_path / "bad.qtanim"
    bad.write_bytes(os.urandom(64))
    fail = subprocess.run([*cmd, "info", str(bad)], capture_output=True, text=True, env=env, timeout=60)
    assert fail.returncode == 1
    assert "Traceback" not in fail.stderr and len(fail.stderr.strip().splitlines()) == 1


# ------------------------------------------------------------------ no display
NO_DISPLAY_LINE = ("qtanimator: no display: run under a desktop session, or use `qtanimator render` for "
                   "headless output")


def test_no_display_is_one_line_and_exit_2_before_qt_starts(tmp_path):
    """Qt would abort the process (SIGABRT) with a misleading xcb message; we say what to do."""
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "QT_QPA_PLATFORM")}
    env["XDG_STATE_HOME"] = str(tmp_path / "state")
    exe = Path(sys.executable).with_name("qtanimator")
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "qtanimator"]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=60, cwd=tmp_path)
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [NO_DISPLAY_LINE] and proc.stdout == ""
    # --version and --help need no display.
    assert subprocess.run([*cmd, "--version"], capture_output=True, text=True, env=env, timeout=60).returncode == 0


@pytest.mark.parametrize("environ, platform, ok", [
    ({}, "linux", False),
    ({"DISPLAY": ":0"}, "linux", True),
    ({"WAYLAND_DISPLAY": "wayland-0"}, "linux", True),
    ({"QT_QPA_PLATFORM": "offscreen"}, "linux", True),
    ({"QT_QPA_PLATFORM": "vnc:size=800x600"}, "linux", True),
    ({"QT_QPA_PLATFORM": "wayland;xcb"}, "linux", False),
    ({"QT_QPA_PLATFORM": "xcb", "DISPLAY": ""}, "linux", False),
    ({"QT_QPA_PLATFORM": "minimal"}, "freebsd14", True),
    ({}, "darwin", True),
    ({}, "win32", True),
])
def test_display_detection(environ, platform, ok):
    from qtanimator.cli import NO_DISPLAY, display_problem

    assert display_problem(environ, platform) == (None if ok else NO_DISPLAY)


def test_verbose_is_an_option(capsys):
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert "--verbose" in out and "log" in out
