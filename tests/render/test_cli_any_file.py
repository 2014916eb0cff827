"""``qtanimator render`` reads any file the program opens; ``--background`` in 3D; ``qtanimator export``."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest
from needs import missing

from qtanimator.cli import main
from qtanimator.cli_export import choose_asset
from qtanimator.render.cli_render import load_scene, options_3d, render_main

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"
BVH = Path("bvh") / "cmu_12_01_walk.bvh"
GLB = Path("gltf") / "CesiumMan.glb"
SKEL = Path("cse169") / "skeleton" / "test.skel"


@pytest.mark.parametrize("path", [BVH, GLB, SKEL])
def test_load_scene_imports_3d_files_into_a_new_document(shared_data: Path, path: Path) -> None:
    doc = load_scene(shared_data / path)
    assert doc.path is None
    assert [a.kind for a in doc.assets.values()] == ["character3d"]


def test_an_unknown_suffix_names_what_is_read(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    bad = tmp_path / "x.txt"
    bad.write_text("hello")
    assert render_main([str(bad), "-o", str(tmp_path / "f"), "--quiet"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and ".bvh" in err[0] and "'.txt'" in err[0]


def _render_3d(tmp_path: Path, scene: Path, *extra: str) -> np.ndarray | None:
    out = tmp_path / "f"
    rc = render_main([str(scene), "-o", str(out), "--frames", "0:0", "--size", "64x48", "--view", "3d",
                      "--quiet", *extra])
    if rc != 0:
        return None  # no OpenGL here: the message is tested in test_cli_render
    return iio.imread(out / "frame_0000.png")


def test_render_a_bvh_file_in_3d(qapp, tmp_path: Path, shared_data: Path) -> None:  # type: ignore[no-untyped-def]
    img = _render_3d(tmp_path, shared_data / BVH)
    if img is None:
        missing("no OpenGL context here")
    assert img.shape[:2] == (48, 64)


def test_background_colour_in_3d(qapp, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    img = _render_3d(tmp_path / "a", SCENES / "arm3d" / "arm3d.qtanim", "--background", "#ff0000")
    if img is None:
        missing("no OpenGL context here")
    assert tuple(img[0, 0, :3]) == (255, 0, 0)  # a corner shows the background, not the viewport's grey
    plain = _render_3d(tmp_path / "b", SCENES / "arm3d" / "arm3d.qtanim")
    assert plain is not None and tuple(plain[0, 0, :3]) != (255, 0, 0)
    clear = _render_3d(tmp_path / "c", SCENES / "arm3d" / "arm3d.qtanim", "--background", "transparent")
    assert clear is not None and clear.shape[2] == 4 and clear[0, 0, 3] == 0


def test_options_3d() -> None:
    assert options_3d(None).background == options_3d(None).__class__().background
    red = options_3d("red")
    assert red.background == (1.0, 0.0, 0.0, 1.0) and red.show_grid
    assert options_3d("transparent").background[3] == 0 and not options_3d("transparent").show_grid
    with pytest.raises(ValueError):
        options_3d("nocolour")


def test_export_writes_glb_from_a_glb_and_a_project(tmp_path: Path, capsys, shared_data: Path) -> None:  # type: ignore[no-untyped-def]  # noqa: E501
    out = tmp_path / "man.glb"
    assert main(["export", str(shared_data / GLB), "-o", str(out)]) == 0
    data = out.read_bytes()
    assert data[:4] == b"glTF"
    length = int.from_bytes(data[12:16], "little")
    doc = json.loads(data[20:20 + length])
    assert doc["skins"] and doc["animations"]
    assert "wrote CesiumMan" in capsys.readouterr().err
    # and back: the written file opens again
    assert [a.kind for a in load_scene(out).assets.values()] == ["character3d"]


def test_export_a_project_character(tmp_path: Path) -> None:
    out = tmp_path / "arm.glb"
    assert main(["export", str(SCENES / "arm3d" / "arm3d.qtanim"), "-o", str(out), "--quiet"]) == 0
    assert out.read_bytes()[:4] == b"glTF"


@pytest.mark.parametrize("args,message", [
    (["{bvh}", "-o", "x.glb"], "no skin or mesh"),
    (["{glb}", "-o", "x.gltf"], ".glb"),
    (["{glb}", "-o", "x.glb", "--asset", "nobody"], "not a 3D character"),
    ([str(SCENES / "pendulum_clock.svg"), "-o", "x.glb"], "no 3D character"),
    (["missing.qtanim", "-o", "x.glb"], "no such"),
])
def test_export_errors_are_one_line(tmp_path: Path, capsys, args: list[str], message: str,  # type: ignore[no-untyped-def]
                                    shared_data: Path) -> None:
    args = [a.replace("{bvh}", str(shared_data / BVH)).replace("{glb}", str(shared_data / GLB)) for a in args]
    args = [str(tmp_path / a) if a.startswith(("x.", "missing")) else a for a in args]
    assert main(["export", *args]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0] and err[0].startswith("qtanimator export:")
    assert not (tmp_path / "x.glb").exists()


def test_choose_asset_wants_a_name_among_several() -> None:
    class A:
        def __init__(self, i: str, kind: str) -> None:
            self.id, self.kind = i, kind

    class D:
        assets = {"a": A("a", "character3d"), "b": A("b", "character3d"), "c": A("c", "cloth")}

    with pytest.raises(ValueError, match="--asset"):
        choose_asset(D(), None)
    assert choose_asset(D(), "b") == "b"


def test_export_runs_as_a_command(tmp_path: Path) -> None:
    out = tmp_path / "arm.glb"
    proc = subprocess.run([sys.executable, "-m", "qtanimator", "export", str(SCENES / "arm3d" / "arm3d.qtanim"),
                           "-o", str(out)], capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    assert out.exists() and "wrote" in proc.stderr
    usage = subprocess.run([sys.executable, "-m", "qtanimator", "export"], capture_output=True, text=True,
                           timeout=120, cwd=ROOT)
    assert usage.returncode == 2 and len(usage.stderr.strip().splitlines()) == 1
