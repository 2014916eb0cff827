"""``qtanimator export SCENE -o OUT.glb [--asset ID]``: write a 3D character as glTF without a window.

SCENE is any file the program opens (see :func:`qtanimator.render.cli_render.load_scene`); the
character and its animation are written by :func:`qtanimator.document.import3d.export_gltf`, the
writer of File ▸ Export glTF.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn

from qtanimator.formats.errors import FormatError


class _OneLineParser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:
        print(f"{self.prog}: {message} (try '{self.prog} --help')", file=sys.stderr)
        raise SystemExit(2)


def _parser() -> argparse.ArgumentParser:
    p = _OneLineParser(prog="qtanimator export",
                       description="Export a 3D character and its animation as a glTF binary (.glb).")
    p.add_argument("scene", help="a project (.qtanim) or a 3D file (.skel, .bvh, .glb, …)")
    p.add_argument("-o", "--output", required=True, help="the .glb file to write")
    p.add_argument("--asset", help="the 3D character to export (needed when the scene has several)")
    p.add_argument("--quiet", action="store_true", help="no summary or warnings on stderr")
    return p


def choose_asset(doc: object, asset: str | None) -> str:
    """The 3D character to export: ``asset``, else the only one; ValueError says why not."""
    from qtanimator.document.character3d import ASSET_KIND

    ids = [a.id for a in doc.assets.values() if a.kind == ASSET_KIND]  # type: ignore[attr-defined]
    if asset is not None:
        if asset not in ids:
            listed = ", ".join(ids) if ids else "none"
            raise ValueError(f"--asset: '{asset}' is not a 3D character of the scene (3D characters: {listed})")
        return asset
    if not ids:
        raise ValueError("the scene has no 3D character to export")
    if len(ids) > 1:
        raise ValueError(f"the scene has {len(ids)} 3D characters ({', '.join(ids)}); pick one with --asset")
    return ids[0]


def export_main(argv: Sequence[str]) -> int:
    """Entry point of ``qtanimator export``; returns the exit status (SystemExit 2 for usage errors)."""
    ns = _parser().parse_args(list(argv))
    out = Path(ns.output)
    try:
        if out.suffix.lower() != ".glb":
            raise ValueError(f"-o must name a .glb file, got '{out.name}'")
        from qtanimator.document.import3d import export_gltf
        from qtanimator.render.cli_render import load_scene

        doc = load_scene(ns.scene)
        aid = choose_asset(doc, ns.asset)
        _result, messages = export_gltf(doc, aid, out)
    except (FormatError, ValueError) as exc:
        print(f"qtanimator export: {' '.join(str(exc).split())}", file=sys.stderr)
        return 1
    except OSError as exc:
        where = exc.filename or out
        print(f"qtanimator export: cannot write '{where}': {exc.strerror or exc}", file=sys.stderr)
        return 1
    if not ns.quiet:
        for m in messages:
            print(f"qtanimator export: {' '.join(m.split())}", file=sys.stderr)
        print(f"wrote {aid} to {out}", file=sys.stderr)
    return 0
