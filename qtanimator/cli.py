"""Command line: ``qtanimator [PATH]``, ``qtanimator render …``, ``qtanimator info …``.

Bad input gives a one-line error on stderr and a non-zero exit status, never a traceback.
Set ``QTANIMATOR_DEBUG=1`` to get the traceback of an unexpected error instead.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NoReturn

from qtanimator import __version__
from qtanimator.formats.errors import FormatError

#: Exit statuses: 1 unreadable input, 2 bad usage, 70 internal error (sysexits EX_SOFTWARE).
EXIT_INPUT = 1
EXIT_USAGE = 2
EXIT_INTERNAL = 70


class OneLineParser(argparse.ArgumentParser):
    """argparse, but a usage error is one line on stderr (and exit status 2)."""

    def error(self, message: str) -> NoReturn:
        print(f"{self.prog}: {message} (try '{self.prog} --help')", file=sys.stderr)
        raise SystemExit(EXIT_USAGE)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (``--help`` and usage errors too)."""
    args = list(sys.argv[1:] if argv is None else argv)
    try:
        if args and args[0] == "info":
            return _info(args[1:])
        if args and args[0] == "render":
            return _render(args[1:])
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
    try:
        from qtanimator.render.cli_render import render_main
    except ImportError as exc:
        if (exc.name or "").startswith("qtanimator.render") or (exc.name or "") in ("PySide6", "OpenGL"):
            _fail(f"rendering is not available in this installation ({exc}).")
            return EXIT_INPUT
        raise
    return int(render_main(args))


def _gui(args: list[str]) -> int:
    parser = OneLineParser(
        prog="qtanimator",
        description="Character animation: 2D SVG rigs with IK and pendulums, a curve editor, "
                    "skinned 3D characters and cloth.",
        epilog="Subcommands: 'qtanimator render --help' renders without a window; "
               "'qtanimator info --help' summarises a file.",
    )
    parser.add_argument("path", nargs="?", help="a project (.qtanim), an SVG character or folder, "
                        "or a 3D file; the demo project when left out")
    parser.add_argument("--version", action="version", version=f"qtanimator {__version__}")
    ns = parser.parse_args(args)

    from qtanimator.paths import demo_project

    path = Path(ns.path) if ns.path else demo_project()
    if ns.path and not path.exists():
        raise FormatError("no such file or folder.", path)

    from PySide6.QtWidgets import QApplication

    from qtanimator.ui.main_window import MainWindow

    # Simulation and autosave workers share the GIL with the UI thread: hand it over every
    # millisecond (Python's default is 5 ms) so the UI's turn comes well inside a frame.
    sys.setswitchinterval(0.001)
    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("qtanimator")
    app.setOrganizationName("qtanimator")
    window = MainWindow()
    window.show()
    if path.exists():
        window.open_path(path)
    return int(app.exec())


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
