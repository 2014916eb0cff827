"""Command line: ``qtanimator [PATH]``, ``qtanimator render …``, ``qtanimator info …``.

Bad input gives a one-line error on stderr and a non-zero exit status, never a traceback.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path

from qtanimator import __version__
from qtanimator.formats.errors import FormatError


def main(argv: Sequence[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    try:
        if args and args[0] == "info":
            return _info(args[1:])
        if args and args[0] == "render":
            from qtanimator.render.cli_render import render_main

            return render_main(args[1:])
        return _gui(args)
    except FormatError as exc:
        print(f"qtanimator: {exc}", file=sys.stderr)
        return 1
    except (OSError, ValueError) as exc:
        print(f"qtanimator: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130


def _gui(args: list[str]) -> int:
    parser = argparse.ArgumentParser(
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

    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("qtanimator")
    app.setOrganizationName("qtanimator")
    window = MainWindow()
    window.show()
    if path.exists():
        window.open_path(path)
    return int(app.exec())


def _info(args: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="qtanimator info",
                                     description="Summarise a file qtanimator can read.")
    parser.add_argument("path", help="any supported file")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    ns = parser.parse_args(args)
    from qtanimator.formats.info import summarize

    summary = summarize(Path(ns.path))
    if ns.json:
        print(json.dumps(summary, indent=2))
    else:
        for key, value in summary.items():
            if isinstance(value, (list, dict)):
                value = json.dumps(value)
            print(f"{key}: {value}")
    return 0
