"""Headless rendering without the command line: open any file as a document, the Qt
application a render needs, and the frames of the 2D view and the options of the 3D view.

Shared by ``qtanimator render`` (:mod:`qtanimator.render.cli_render`), ``qtanimator export``
and the ``--jobs`` / ``--dask`` workers (:mod:`qtanimator.render.parallel`).
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from qtanimator.formats.errors import FormatError


def load_scene(path: str | os.PathLike[str]) -> Any:
    """A document for any file the program opens: a project, an SVG character / folder, or a
    3D file (``.skel``, ``.bvh``, ``.glb`` …, imported into a new document)."""
    from qtanimator.document import Document, open_document

    p = Path(path)
    if not p.exists():
        raise FormatError("no such file or folder.", p)
    if p.is_file() and p.suffix.lower() in (".qtanim", ".json"):
        return open_document(p)
    if p.is_dir() or p.suffix.lower() == ".svg":
        from qtanimator.document.character2d import add_characters_command

        doc = Document()
        add_characters_command(doc, p, new_project_range=True).do(doc)  # 0…300, as opening it in the GUI
        doc.path = None
        return doc
    from qtanimator.document.import3d import SUFFIXES, import_file

    if p.is_file() and p.suffix.lower() in SUFFIXES:
        # as File ▸ Open does: a new document with the file imported (its clip's frame range and fps)
        doc = Document()
        import_file(doc, p).command.do(doc)
        doc.path = None
        return doc
    raise FormatError(f"qtanimator reads projects (.qtanim), SVG characters and 3D files "
                      f"({', '.join(SUFFIXES)}), not '{p.suffix}' files.", p)


def ensure_gui_app() -> Any:
    if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        if not os.environ.get("QT_QPA_PLATFORM"):
            os.environ["QT_QPA_PLATFORM"] = "offscreen"
    from PySide6.QtGui import QGuiApplication

    return QGuiApplication.instance() or QGuiApplication(["qtanimator-render"])


def frames_2d(doc: Any, times: Sequence[float], size: tuple[int, int], background: str) -> Iterator[np.ndarray]:
    """RGBA frames of the 2D characters at ``times`` with a steady camera."""
    from qtanimator.render.painter2d import animation_bounds, image_to_array, render_frame

    view = animation_bounds(doc, times)
    for t in times:
        yield image_to_array(render_frame(doc, t, size, background, view=view))


def options_3d(background: str | None) -> Any:
    """The 3D view options of a render: no skeleton, no light markers, ``background`` (a colour
    name, #rrggbb or 'transparent'; None: the viewport's)."""
    from qtanimator.render.gl.renderer import ViewOptions
    from qtanimator.render.painter2d import background_color

    options = ViewOptions(show_skeleton=False, show_lights=False)
    if background is not None:
        c = background_color(background)  # ValueError for a bad colour
        options.background = (c.redF(), c.greenF(), c.blueF(), c.alphaF())
        if c.alpha() == 0:
            options.show_grid = False  # a transparent render is for compositing: no floor grid
    return options
