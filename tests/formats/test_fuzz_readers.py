"""Every reader, fed mutated real files: only FormatError may come out.

Each reader gets a small real file (the project's scenes or the shared samples) mutated by
hypothesis: bytes flipped, inserted, deleted, runs duplicated, the file cut short. The
seed is fixed (``derandomize``) so CI sees the same 500 cases per reader every run; a
per-test timeout turns a hang into a failure.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from needs import shared_data_path

from qtanimator.formats import FormatError
from qtanimator.formats.anim import load_anim
from qtanimator.formats.attach import load_attach
from qtanimator.formats.bvh import load_bvh
from qtanimator.formats.gltf import import_gltf
from qtanimator.formats.morph import load_morph
from qtanimator.formats.obj import load_obj
from qtanimator.formats.project import load_project
from qtanimator.formats.skel import load_skel
from qtanimator.formats.skin import load_skin
from qtanimator.formats.svg_rig import load_characters

REPO = Path(__file__).resolve().parents[2]
OBJ = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nvt 0 0\nf 1/1/1 2/1/1 3/1/1\nf 2 4 3\n"
ATTACH = b"0.5 0.5 0\n1 0 0\n0 1 0\n0.25 0.25 0.5\n"
SKIN = (b"positions 3 {\n 0 0 0\n 1 0 0\n 0 1 0\n}\nnormals 3 {\n 0 0 1\n 0 0 1\n 0 0 1\n}\n"
        b"skinweights 3 {\n 1 0 1.0\n 2 0 0.5 1 0.5\n 1 1 1.0\n}\ntriangles 1 {\n 0 1 2\n}\n"
        b"bindings 2 {\n matrix {\n 1 0 0\n 0 1 0\n 0 0 1\n 0 0 0\n }\n"
        b" matrix {\n 1 0 0\n 0 1 0\n 0 0 1\n 0 1 0\n }\n}\n")

#: suffix → (reader, where the seed file comes from: a path in the repository, a path inside
#: the sample data as a string (``tests/needs.py``: skipped without it, failed in CI), or bytes)
SEEDS: dict[str, tuple[Callable[[Path], Any], Path | str | bytes]] = {
    ".anim": (load_anim, REPO / "scenes" / "arm3d" / "arm_wave.anim"),
    ".skel": (load_skel, REPO / "scenes" / "arm3d" / "arm.skel"),
    ".skin": (load_skin, SKIN),
    ".obj": (load_obj, OBJ),
    ".attach": (lambda p: load_attach(p, 4, 4), ATTACH),
    ".morph": (load_morph, "cse169/head/head2.morph"),
    ".bvh": (load_bvh, "bvh/pybvh_rotation_first_root.bvh"),
    ".gltf": (import_gltf, "gltf/SimpleSkin.gltf"),
    ".glb": (import_gltf, "gltf/RiggedSimple.glb"),
    ".svg": (load_characters, "cmu-animator/scenes/arm.svg"),
    ".qtanim": (load_project, REPO / "scenes" / "flappy_hop.qtanim"),
}

edits = st.lists(st.tuples(st.sampled_from(["flip", "insert", "delete", "repeat", "cut"]),
                           st.floats(0.0, 1.0, allow_nan=False), st.integers(0, 255), st.integers(1, 64)),
                 min_size=1, max_size=6)


def mutate(data: bytes, ops: list[tuple[str, float, int, int]]) -> bytes:
    buf = bytearray(data)
    for kind, where, byte, size in ops:
        if not buf:
            break
        i = min(int(where * len(buf)), len(buf) - 1)
        if kind == "flip":
            buf[i] = byte
        elif kind == "insert":
            buf[i:i] = bytes([byte]) * size
        elif kind == "delete":
            del buf[i:i + size]
        elif kind == "repeat":
            buf[i:i] = buf[i:i + size] * 4
        else:
            del buf[i:]
    return bytes(buf)


@pytest.mark.timeout(300)
@pytest.mark.parametrize("suffix", sorted(SEEDS))
def test_mutated_files_give_format_error_only(tmp_path: Path, suffix: str) -> None:
    reader, source = SEEDS[suffix]
    if isinstance(source, str):
        source = shared_data_path(source)
    seed = source if isinstance(source, bytes) else source.read_bytes()
    reader(_write(tmp_path, suffix, seed))  # the seed itself reads

    @settings(max_examples=500, derandomize=True, deadline=None, database=None,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
    @given(ops=edits)
    def check(ops: list[tuple[str, float, int, int]]) -> None:
        path = _write(tmp_path, suffix, mutate(seed, ops))
        try:
            reader(path)
        except FormatError:
            pass

    check()


def _write(folder: Path, suffix: str, data: bytes) -> Path:
    path = folder / f"fuzz{suffix}"
    path.write_bytes(data)
    return path
