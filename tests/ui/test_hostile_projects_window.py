"""The window survives every hostile project of issue 31 (part 4, "Crashes and errors that
are not FormatError"): the real MainWindow in a child process (``hostile_project_child.py``;
a segfault there is an exit status) opens a good project, then each hostile one: each shows
the reader's sentence naming the property, no "unexpected error" dialog, and the good
project stays open. Numbers at the bounds, and a channel no project may hold put straight
into the document, give the curve editor and the dope sheet finite ranges.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from qtanimator.ui.view3d_camera import MAX_FRAMED_COORDINATE, framable

CHILD = Path(__file__).with_name("hostile_project_child.py")
REPO = Path(__file__).resolve().parents[2]
PENCIL = {"id": "pencil", "kind": "character2d", "source": "pencil.svg"}


def write(folder: Path, name: str, assets: list[dict[str, Any]], channels: dict[str, Any] | None = None) -> str:
    path = folder / name
    path.write_text(json.dumps({"format": "qtanimator-project", "version": 2, "parameters": {},
                                "assets": assets, "channels": channels or {}}), encoding="utf-8")
    return str(path)


def x_channel(times: list[float], values: list[float], **more: Any) -> dict[str, Any]:
    return {"pencil//x": {"times": times, "values": values, **more}}


#: file name → words its error must show (the property, as the file spells it).
HOSTILE: dict[str, tuple[list[dict[str, Any]], dict[str, Any], list[str]]] = {
    "tiny.qtanim": ([PENCIL], x_channel([0, 5e-324], [0, 1], pre="cycle", post="cycle"), ['"times"']),
    "value.qtanim": ([PENCIL], x_channel([0, 1], [0, 1e308]), ['"values"']),
    "time.qtanim": ([PENCIL], x_channel([0, -1e308], [0, 1]), ['"times"']),
    "tangent.qtanim": ([PENCIL], x_channel([0, 1], [0, 1], out=1e308), ['"out"']),
    "index_list.qtanim": ([dict(PENCIL, properties={"index": [0]})], {}, ['"index"']),
    "index_text.qtanim": ([dict(PENCIL, properties={"index": "zero"})], {}, ['"index"']),
    "skin_file.qtanim": ([{"id": "arm", "kind": "character3d", "source": "pencil.svg",
                           "properties": {"skin_file": 123}}], {}, ['"skin_file"']),
    "cloth.qtanim": ([{"id": "sheet", "kind": "cloth", "properties": {"width": 1e308}}], {}, ["sheet.width"]),
}


def test_the_window_keeps_its_document_through_every_hostile_project(tmp_path: Path) -> None:
    (tmp_path / "pencil.svg").write_bytes((REPO / "scenes" / "pencil.svg").read_bytes())
    good = write(tmp_path, "good.qtanim", [PENCIL], x_channel([0.0, 0.5, 1.0], [0.0, 10.0, 0.0]))
    edge = write(tmp_path, "edge.qtanim", [PENCIL], x_channel(
        [-1e6, -1e6 + 1e-6, 0.0, 1e6], [-1e9, 1e9, 0.0, 1.0], pre="cycle_offset", post="cycle_offset",
        **{"in": 1e9, "out": -1e9}))
    hostile = [write(tmp_path, name, assets, channels) for name, (assets, channels, _) in HOSTILE.items()]
    env = dict(os.environ)
    env.update({"XDG_STATE_HOME": str(tmp_path / "state"), "QTANIMATOR_SETTINGS_DIR": str(tmp_path / "settings"),
                "PYTHONPATH": os.pathsep.join([str(REPO), str(REPO / "tests")]), "QT_QPA_PLATFORM": "offscreen"})
    proc = subprocess.run([sys.executable, str(CHILD), good, edge, *hostile], env=env, cwd=str(tmp_path),
                          capture_output=True, text=True, timeout=240)
    assert proc.returncode == 0, f"exit {proc.returncode}\n{proc.stderr[-4000:]}"
    lines = [line for line in proc.stdout.splitlines() if line.startswith("HOSTILE-RESULT ")]
    assert lines, proc.stdout[-2000:] + proc.stderr[-2000:]
    result = json.loads(lines[-1].removeprefix("HOSTILE-RESULT "))
    assert result["good_opened"]
    assert result["good"]["assets"] == ["pencil"]
    for seen in result["hostile"]:
        words = HOSTILE[seen["file"]][2]
        assert not seen["opened"], seen
        assert seen["same_document"], seen
        assert len(seen["dialogs"]) == 1, seen
        title, text = seen["dialogs"][0]
        assert title == "Cannot open file"
        assert text.startswith(seen["file"] + ": "), text
        for word in words:
            assert word in text, text
    assert [s["file"] for s in result["hostile"]] == list(HOSTILE)
    # Numbers at the bounds open and frame; a channel beyond them draws nothing NaN.
    assert result["edge_opened"] and result["edge_dialogs"] == []
    assert result["raw_shown"]
    assert result["finite"], result
    assert result["unexpected_dialogs"] == []
    assert "Cannot set range" not in proc.stderr and "Traceback" not in proc.stderr, proc.stderr[-3000:]
    assert "Cannot set range" not in result["log"]


@pytest.mark.parametrize("bounds", [
    (np.array([0.0, 0.0, 0.0]), np.array([1e308, 1.0, 1.0])),
    (np.array([np.nan, 0.0, 0.0]), np.array([1.0, 1.0, 1.0])),
    (np.array([-np.inf, 0.0, 0.0]), np.array([1.0, 1.0, 1.0])),
    (np.array([0.0, 0.0, 0.0]), np.array([2e9, 1.0, 1.0])),
    None,
])
def test_the_3d_camera_frames_only_a_finite_box_within_reach(bounds: Any) -> None:
    assert framable(bounds) is None


def test_the_3d_camera_frames_a_box_at_the_limit() -> None:
    lo, hi = np.array([-MAX_FRAMED_COORDINATE, 0.0, 0.0]), np.array([MAX_FRAMED_COORDINATE, 1.0, 1.0])
    found = framable((lo, hi))
    assert found is not None
    from qtanimator.render.gl.camera import OrbitCamera

    camera = OrbitCamera()
    camera.frame(*found)
    assert all(math.isfinite(v) for v in (*camera.target, camera.distance))
    assert np.isfinite(camera.view()).all()
