"""Every reader, and ``qtanimator info``, on paths that are not model files.

Missing files, folders, devices and pipes (reading ``/dev/zero`` or a FIFO would never
end), NUL bytes in the path, empty files and random bytes: each gives a FormatError with
the file's name, quickly, and nothing else.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from qtanimator.formats import FormatError
from qtanimator.formats.anim import load_anim
from qtanimator.formats.attach import load_attach
from qtanimator.formats.bvh import load_bvh
from qtanimator.formats.gltf import import_gltf
from qtanimator.formats.info import summarize
from qtanimator.formats.morph import load_morph
from qtanimator.formats.obj import load_obj
from qtanimator.formats.project import load_project
from qtanimator.formats.skel import load_skel
from qtanimator.formats.skin import load_skin
from qtanimator.formats.svg_rig import load_characters

READERS: dict[str, Callable[[Path], Any]] = {
    ".anim": load_anim,
    ".skel": load_skel,
    ".skin": load_skin,
    ".obj": load_obj,
    ".attach": lambda p: load_attach(p, 3, 4),
    ".morph": load_morph,
    ".bvh": load_bvh,
    ".glb": import_gltf,
    ".gltf": import_gltf,
    ".svg": load_characters,
    ".qtanim": load_project,
}
SUFFIXES = sorted(READERS)


def _calls(path: Path) -> list[Callable[[], Any]]:
    reader = READERS[path.suffix]
    return [lambda: reader(path), lambda: summarize(path)]


def _special(tmp_path: Path, kind: str, suffix: str) -> Path:
    path = tmp_path / f"thing{suffix}"
    if kind == "missing":
        pass
    elif kind == "empty":
        path.write_bytes(b"")
    elif kind == "random bytes":
        path.write_bytes(bytes(range(256)) * 8)
    elif kind == "device":
        if not os.path.exists("/dev/zero"):
            pytest.skip("no /dev/zero here")
        path.symlink_to("/dev/zero")
    elif kind == "pipe":
        if not hasattr(os, "mkfifo"):
            pytest.skip("no named pipes here")
        os.mkfifo(path)
    return path


@pytest.mark.timeout(60)
@pytest.mark.parametrize("kind", ["missing", "empty", "random bytes", "device", "pipe"])
@pytest.mark.parametrize("suffix", SUFFIXES)
def test_only_format_error_and_no_hang(tmp_path: Path, suffix: str, kind: str) -> None:
    path = _special(tmp_path, kind, suffix)
    for call in _calls(path):
        with pytest.raises(FormatError) as info:
            call()
        assert path.name in str(info.value)


@pytest.mark.parametrize("suffix", [s for s in SUFFIXES if s != ".svg"])
def test_a_folder_is_not_a_file(tmp_path: Path, suffix: str) -> None:
    folder = tmp_path / f"folder{suffix}"
    folder.mkdir()
    with pytest.raises(FormatError):
        READERS[suffix](folder)


@pytest.mark.parametrize("suffix", SUFFIXES)
def test_a_nul_byte_in_the_path_is_a_format_error(tmp_path: Path, suffix: str) -> None:
    with pytest.raises(FormatError):
        READERS[suffix](Path(str(tmp_path / "a\0b") + suffix))


@pytest.mark.timeout(60)
def test_a_gltf_buffer_that_points_at_a_device_is_refused(tmp_path: Path) -> None:
    if not os.path.exists("/dev/zero"):
        pytest.skip("no /dev/zero here")
    gltf = tmp_path / "scene.gltf"
    gltf.write_text('{"asset": {"version": "2.0"}, "buffers": [{"uri": "/dev/zero", "byteLength": 4}]}')
    with pytest.raises(FormatError, match="outside the glTF's folder"):
        import_gltf(gltf)
    # A pipe inside the folder is refused as a pipe (reading it would never end).
    os.mkfifo(tmp_path / "pipe.bin")
    gltf.write_text('{"asset": {"version": "2.0"}, "buffers": [{"uri": "pipe.bin", "byteLength": 4}]}')
    with pytest.raises(FormatError, match="cannot be read"):
        import_gltf(gltf)
