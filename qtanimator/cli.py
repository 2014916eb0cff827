"""Command line: ``qtanimator [PATH]``, ``qtanimator render …``, ``qtanimator export …``,
``qtanimator info …``.

Bad input gives a one-line error on stderr and a non-zero exit status, never a traceback.
Set ``QTANIMATOR_DEBUG=1`` to get the traceback of an unexpected error instead.

The GUI start checks for a display before Qt is started (Qt would abort the process), logs
to a rotating file under the XDG state folder (:mod:`qtanimator.applog`; ``--verbose`` logs
debug messages and copies the log to stderr) and installs the exception hook of
:mod:`qtanimator.ui.errors`, so that an error in the window is logged and shown.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, NoReturn

from qtanimator import __version__, applog
from qtanimator.formats.errors import FormatError

#: Exit statuses: 1 unreadable input, 2 bad usage (or no display for the GUI), 70 internal
#: error (sysexits EX_SOFTWARE).
EXIT_INPUT = 1
EXIT_USAGE = 2
EXIT_INTERNAL = 70

NO_DISPLAY = "no display: run under a desktop session, or use `qtanimator render` for headless output"

#: Qt platform plugins that need no window system (``QT_QPA_PLATFORM``).
HEADLESS_PLATFORMS = frozenset({"offscreen", "minimal", "minimalegl", "vnc", "eglfs", "linuxfb", "vkkhrdisplay"})


class OneLineParser(argparse.ArgumentParser):
    """argparse, but a usage error is one line on stderr (and exit status 2)."""

    def error(self, message: str) -> NoReturn:
        print(f"{self.prog}: {message} (try '{self.prog} --help')", file=sys.stderr)
        raise SystemExit(EXIT_USAGE)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (``--help`` and usage errors too)."""
    args = list(sys.argv[1:] if argv is None else argv)
    # A native crash (Qt, OpenGL, the interpreter) leaves its stack on stderr; the GUI moves it
    # into the log folder once it starts (_gui).
    applog.enable_crash_traces(to_log_folder=False)
    try:
        if args and args[0] == "info":
            return _info(args[1:])
        if args and args[0] == "render":
            return _render(args[1:])
        if args and args[0] == "export":
            from qtanimator.cli_export import export_main

            return int(export_main(args[1:]))
        return _gui(args)
    except SystemExit as exc:  # argparse: --help, --version and usage errors
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else EXIT_USAGE)
    except FormatError as exc:
        _fail(str(exc))
        return EXIT_INPUT
    except OSError as exc:
        where = f"{Path(exc.filename).name}: " if exc.filename else ""
        _fail(f"{where}{exc.strerror or exc}")
        return EXIT_INPUT
    except ValueError as exc:
        _fail(str(exc))
        return EXIT_INPUT
    except KeyboardInterrupt:
        return 130
    except Exception as exc:
        if os.environ.get("QTANIMATOR_DEBUG"):
            raise
        _fail(f"internal error: {type(exc).__name__}: {exc} (set QTANIMATOR_DEBUG=1 for details)")
        return EXIT_INTERNAL


def _fail(message: str) -> None:
    text = " ".join(message.split())  # one line, whatever the message holds
    print(f"qtanimator: {text}", file=sys.stderr)


def _render(args: list[str]) -> int:
    from qtanimator.render.interrupt import RenderInterrupted, report_interrupted, signals_held

    try:
        # SIGINT / SIGTERM wait while the renderer and Qt's bindings load (a KeyboardInterrupt
        # while PySide6 initialises aborts Python), then stop the render with its usual message.
        with signals_held():
            import PySide6.QtCore
            import PySide6.QtGui  # noqa: F401

            from qtanimator.render.cli_render import render_main
    except RenderInterrupted as exc:
        return report_interrupted(exc)
    except ImportError as exc:
        if (exc.name or "").startswith("qtanimator.render") or (exc.name or "") in ("PySide6", "OpenGL"):
            _fail(f"rendering is not available in this installation ({exc}).")
            return EXIT_INPUT
        raise
    return int(render_main(args))


def display_problem(environ: Mapping[str, str] | None = None, platform: str | None = None) -> str | None:
    """Why the GUI cannot start here, or None. Only X11 / Wayland systems are checked: there
    Qt aborts the whole process (SIGABRT) when it finds no display."""
    env = os.environ if environ is None else environ
    system = sys.platform if platform is None else platform
    if system.startswith(("win", "cygwin", "darwin")):
        return None
    wanted = [p.split(":", 1)[0].strip() for p in env.get("QT_QPA_PLATFORM", "").split(";") if p.strip()]
    if any(p in HEADLESS_PLATFORMS for p in wanted):
        return None
    if env.get("DISPLAY") or env.get("WAYLAND_DISPLAY"):
        return None
    return NO_DISPLAY


def _gui(args: list[str]) -> int:
    parser = OneLineParser(
        prog="qtanimator",
        description="Character animation: 2D SVG rigs with IK and pendulums, a curve editor, "
                    "skinned 3D characters and cloth.",
        epilog="Subcommands: 'qtanimator render --help' renders without a window; "
               "'qtanimator export --help' writes a 3D character as glTF; "
               "'qtanimator info --help' summarises a file. "
               f"The log file is {applog.log_path()}.",
    )
    parser.add_argument("path", nargs="?", help="a project (.qtanim), an SVG character or folder, "
                        "or a 3D file; the demo project when left out")
    parser.add_argument("--version", action="version", version=f"qtanimator {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true",
                        help="log debug messages, to the log file and to stderr")
    ns = parser.parse_args(args)

    from qtanimator.paths import demo_project

    path = Path(ns.path) if ns.path else demo_project()
    if ns.path and not path.exists():
        raise FormatError("no such file or folder.", path)
    problem = display_problem()
    if problem is not None:
        _fail(problem)
        return EXIT_USAGE

    log_file = applog.setup_logging(ns.verbose)
    log = logging.getLogger("qtanimator")
    crash_log = applog.enable_crash_traces(to_log_folder=True)
    log.info("qtanimator %s starting (Python %s), log %s, native crash traces in %s", __version__,
             sys.version.split()[0], log_file, crash_log or "stderr")

    from PySide6.QtGui import QGuiApplication, QIcon
    from PySide6.QtWidgets import QApplication

    from qtanimator.paths import APP_ID, app_icon_path
    from qtanimator.ui.errors import install_excepthook
    from qtanimator.ui.main_window import MainWindow

    # The desktop entry's name: Wayland compositors match windows to it (icon, grouping).
    QGuiApplication.setDesktopFileName(APP_ID)
    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("qtanimator")
    app.setOrganizationName("qtanimator")
    app.setApplicationVersion(__version__)
    if isinstance(app, QGuiApplication):
        app.setWindowIcon(QIcon(str(app_icon_path())))
    install_excepthook()
    window = MainWindow()
    window.show()
    if path.exists():
        window.open_path(path)
    status = int(app.exec())
    log.info("qtanimator exits with status %d", status)
    return status


def _info(args: list[str]) -> int:
    parser = OneLineParser(prog="qtanimator info",
                           description="Summarise a file qtanimator can read: channels, keys and "
                                       "time ranges; joints, vertices and frames where the format has them.")
    parser.add_argument("path", help="any supported file (.qtanim, .anim, .skel, .skin, .obj, .bvh, "
                        ".gltf/.glb, .svg or a folder of SVG characters)")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    ns = parser.parse_args(args)
    from qtanimator.formats.info import summarize

    summary = summarize(Path(ns.path))
    if ns.json:
        print(json.dumps(summary, indent=2, default=_plain))
    else:
        for key, value in summary.items():
            if isinstance(value, (list, dict)):
                value = json.dumps(value, default=_plain)
            print(f"{key}: {value}")
    return 0


def _plain(value: Any) -> Any:
    """JSON for the numpy numbers and arrays a summariser may return."""
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"{type(value).__name__} is not JSON data")
