"""Write the cloth scene ``scenes/cloth/cloth.qtanim`` (run: ``.venv/bin/python scenes/tools/make_cloth.py``).

A flag: a 1.6 m × 1.0 m mass-spring cloth (16 × 24 particles, 1 kg) hanging in the
vertical x-y plane, its left edge pinned to an imaginary pole at x = 0, blown by a gusty
wind along +x with a little −z. It is built with :func:`qtanimator.document.cloth.add_cloth_command`
and saved with :func:`qtanimator.document.save_document`, so the file is exactly what the
program writes; open it and use the cloth and wind panels to change it.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from qtanimator.core.cloth import ClothParams, pins_from_cells
from qtanimator.document import Document, save_document
from qtanimator.document.cloth import add_cloth_command

HERE = Path(__file__).resolve().parent
OUT = HERE.parent / "cloth"
ROWS, COLS = 16, 24


def flag_params() -> ClothParams:
    return ClothParams(
        integrator="symplectic",
        rows=ROWS, cols=COLS, width=1.6, height=1.0, total_mass=1.0,
        structural_stiffness=200.0, structural_damping=0.2,
        shear_stiffness=80.0, shear_damping=0.1,
        bend_stiffness=8.0, bend_damping=0.02,
        drag_coefficient=1.0, air_density=1.225,
        wind=(7.0, 0.0, -1.0), turbulence=0.35, turbulence_seed=7,
        ground_enabled=True, ground_height=0.0,
        pin_mode="custom", custom_pins=pins_from_cells(COLS, [(r, 0) for r in range(ROWS)]),
        substeps=16, origin=(0.8, 2.4, 0.0), orientation=(0.0, 0.0, 0.0),
    )


def build() -> Document:
    doc = Document(parameters={"fps": 60.0, "frame_start": 0, "frame_end": 240})
    add_cloth_command(doc, flag_params(), asset_id="flag").do(doc)
    return doc


def write(out: Path) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    p = out / "cloth.qtanim"
    save_document(build(), p)
    return [p]


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description="Write the cloth (flag) scene.")
    ap.add_argument("--out", type=Path, default=OUT, help="output folder (default: scenes/cloth/)")
    ns = ap.parse_args(argv)
    for p in write(ns.out):
        print(f"wrote {p}")


if __name__ == "__main__":
    main()
