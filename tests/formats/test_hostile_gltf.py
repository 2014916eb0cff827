"""Hostile glTF files: buffers that point outside the glTF's folder, and small files that
would expand into gigabytes. Each must be refused with a FormatError naming the problem."""

from __future__ import annotations

import json
import os
import struct
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from qtanimator.formats.errors import FormatError
from qtanimator.formats.gltf import import_gltf
from qtanimator.formats.limits import MAX_JOINTS

#: Every file the process opens while the recorder is on (the ``open`` audit event sees the
#: opens of builtins.open, io.open and Path.open alike). An audit hook cannot be removed,
#: so it is installed once and switched on and off.
_OPENED: list[str] | None = None


def _audit(event: str, args: tuple) -> None:  # type: ignore[type-arg]
    if event == "open" and _OPENED is not None and isinstance(args[0], (str, bytes, os.PathLike)):
        name = os.fsdecode(args[0])
        if not name.endswith((".py", ".pyc", ".so")):  # Python importing its own modules
            _OPENED.append(name)


sys.addaudithook(_audit)


def opened_during(fn):  # type: ignore[no-untyped-def]
    global _OPENED
    _OPENED = []
    try:
        fn()
    finally:
        seen, _OPENED = _OPENED, None
    return [os.path.realpath(p) for p in seen]


def gltf_with_buffer(folder: Path, uri: str, length: int = 12) -> Path:
    """A triangle whose positions come from buffer ``uri``."""
    doc = {
        "asset": {"version": "2.0"},
        "buffers": [{"uri": uri, "byteLength": length}],
        "bufferViews": [{"buffer": 0, "byteLength": length}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 1, "type": "VEC3"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0}],
    }
    path = folder / "scene.gltf"
    path.write_text(json.dumps(doc))
    return path


OUTSIDE = ["/etc/passwd", "../../../../../../../../etc/passwd", "%2e%2e/%2e%2e/%2e%2e/%2e%2e/etc/passwd",
           "/proc/self/environ", "sub/../../outside.bin", "file:///etc/passwd"]


@pytest.mark.parametrize("uri", OUTSIDE)
def test_a_buffer_outside_the_folder_is_refused_and_never_opened(tmp_path: Path, uri: str) -> None:
    folder = tmp_path / "asset"
    folder.mkdir()
    (folder / "sub").mkdir()
    (tmp_path / "outside.bin").write_bytes(b"\0" * 64)
    path = gltf_with_buffer(folder, uri)

    def read() -> None:
        with pytest.raises(FormatError, match="outside the glTF's folder|not a local file"):
            import_gltf(path)

    opened = opened_during(read)
    inside = os.path.realpath(folder)
    assert opened == [os.path.realpath(path)], opened  # the glTF itself and nothing else
    assert all(p.startswith(inside + os.sep) for p in opened)


def test_a_symbolic_link_that_leads_out_of_the_folder_is_refused(tmp_path: Path) -> None:
    folder = tmp_path / "asset"
    folder.mkdir()
    secret = tmp_path / "secret.bin"
    secret.write_bytes(struct.pack("<3f", 1.0, 2.0, 3.0))
    (folder / "link.bin").symlink_to(secret)
    path = gltf_with_buffer(folder, "link.bin")

    def read() -> None:
        with pytest.raises(FormatError, match="outside the glTF's folder"):
            import_gltf(path)

    assert os.path.realpath(secret) not in opened_during(read)


def test_buffers_beside_and_below_the_gltf_are_read(tmp_path: Path) -> None:
    folder = tmp_path / "asset"
    (folder / "data dir").mkdir(parents=True)
    (folder / "data dir" / "tri.bin").write_bytes(struct.pack("<3f", 1.0, 2.0, 3.0))
    scene = import_gltf(gltf_with_buffer(folder, "data%20dir/tri.bin"))
    assert scene.meshes[0].primitives[0].positions.tolist() == [[1.0, 2.0, 3.0]]
    # ``..`` that stays inside is fine too.
    scene = import_gltf(gltf_with_buffer(folder, "data%20dir/../data%20dir/tri.bin"))
    assert scene.meshes[0].primitives[0].positions.tolist() == [[1.0, 2.0, 3.0]]


# ------------------------------------------------------------------ time and memory
def run_limited(script: str, timeout: float = 30.0, memory: int = 1 << 30) -> subprocess.CompletedProcess[str]:
    """Run ``script`` in a fresh interpreter with at most ``memory`` bytes of address space;
    the timeout is a limit for a loaded CI machine, not a measurement."""
    prelude = textwrap.dedent(f"""
        import resource
        resource.setrlimit(resource.RLIMIT_AS, ({memory}, {memory}))
    """)
    return subprocess.run([sys.executable, "-c", prelude + textwrap.dedent(script)], capture_output=True,
                          text=True, timeout=timeout)


def import_in_limited_process(path: Path) -> subprocess.CompletedProcess[str]:
    """import_gltf(path) in a limited child process; prints REFUSED and the message."""
    return run_limited(f"""
        from qtanimator.formats.gltf import import_gltf
        from qtanimator.formats.errors import FormatError
        try:
            import_gltf({str(path)!r})
        except FormatError as e:
            print("REFUSED", e)
    """)


def zero_accessor_bomb(path: Path, accessors: int = 60, count: int = 1 << 20) -> None:
    """A file of a few kilobytes: many MAT4 accessors of a million elements each with no
    buffer view (all zeros by the specification), used as inverse bind matrices."""
    doc = {
        "asset": {"version": "2.0"},
        "accessors": [{"componentType": 5126, "count": count, "type": "MAT4"} for _ in range(accessors)],
        "skins": [{"joints": [0], "inverseBindMatrices": a} for a in range(accessors)],
        "nodes": [{}],
    }
    path.write_text(json.dumps(doc))


def test_accessors_sharing_one_view_cannot_expand_without_bound(tmp_path: Path) -> None:
    path = tmp_path / "bomb.gltf"
    zero_accessor_bomb(path)
    assert path.stat().st_size < 8192
    result = import_in_limited_process(path)
    assert "REFUSED" in result.stdout and "exceeds qtanimator's limit" in result.stdout, result.stderr[-2000:]


@pytest.mark.parametrize("joints", [MAX_JOINTS + 1, 20_000, 60_000])  # the 20 k and 60 k
def test_a_skin_with_too_many_joints_is_refused(tmp_path: Path, joints: int) -> None:
    path = tmp_path / "joints.gltf"
    doc = {"asset": {"version": "2.0"}, "nodes": [{} for _ in range(joints)],
           "skins": [{"joints": list(range(joints))}]}
    path.write_text(json.dumps(doc))
    result = import_in_limited_process(path)
    assert "REFUSED" in result.stdout and f"{MAX_JOINTS} joints" in result.stdout, result.stderr[-2000:]


def test_a_skin_within_the_joint_limit_still_opens(tmp_path: Path) -> None:
    path = tmp_path / "joints.gltf"
    n = 300
    doc = {"asset": {"version": "2.0"}, "nodes": [{"children": [i + 1]} for i in range(n - 1)] + [{}],
           "skins": [{"joints": list(range(n))}]}
    path.write_text(json.dumps(doc))
    assert len(import_gltf(path).skins[0].joints) == n


def test_too_many_vertices_are_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from qtanimator.formats.gltf import reader

    monkeypatch.setattr(reader, "MAX_VERTICES", 2)  # the limit is counted over every primitive
    path = gltf_with_buffer(tmp_path, "tri.bin", 12)
    (tmp_path / "tri.bin").write_bytes(struct.pack("<3f", 1.0, 2.0, 3.0))
    doc = json.loads(path.read_text())
    doc["meshes"][0]["primitives"] *= 3
    path.write_text(json.dumps(doc))
    with pytest.raises(FormatError, match="limit of 2 vertices"):
        import_gltf(path)
    doc["meshes"][0]["primitives"] = doc["meshes"][0]["primitives"][:2]
    path.write_text(json.dumps(doc))
    assert len(import_gltf(path).meshes[0].primitives) == 2


def test_a_huge_data_uri_is_refused_before_it_is_decoded(tmp_path: Path) -> None:
    """A 100 MB data URI (the issue measured 300 MB at 1.4 GB of memory) is refused by its
    length, within 1 GB, before base64 decodes it."""
    path = tmp_path / "big.gltf"
    payload = "A" * (100 << 20)
    path.write_text('{"asset": {"version": "2.0"}, "buffers": [{"byteLength": 4, "uri": '
                    '"data:application/octet-stream;base64,' + payload + '"}]}')
    del payload
    result = import_in_limited_process(path)
    assert "REFUSED" in result.stdout and "MAX_DATA_URI_BYTES" in result.stdout, result.stderr[-2000:]


def test_a_project_reads_outside_its_folder_only_what_it_records_as_chosen(tmp_path: Path) -> None:
    from qtanimator.formats.project import load_project

    folder = tmp_path / "project"
    (folder / "art").mkdir(parents=True)
    (folder / "art" / "a.svg").write_text("<svg/>")
    (tmp_path / "elsewhere.svg").write_text("<svg/>")

    def project(source: str, outside: list[str] | None = None) -> Path:
        asset = {"id": "a", "kind": "character2d", "source": source, "properties": {}}
        if outside is not None:
            asset["outside"] = outside
        path = folder / "p.qtanim"
        path.write_text(json.dumps({"format": "qtanimator-project", "version": 2, "parameters": {},
                                    "assets": [asset], "channels": {}}))
        return path

    assert load_project(project("art/a.svg")).assets[0].source == str((folder / "art" / "a.svg").resolve())
    for hostile in ("/etc/passwd", "../../../../../etc/passwd", "art/../../elsewhere.svg"):
        with pytest.raises(FormatError, match="outside the project's folder"):
            load_project(project(hostile))
    # Chosen by the user (File ▸ Open, Save As without collecting): recorded, so allowed.
    assert load_project(project("../elsewhere.svg", ["source"])).assets[0].source == str(
        (tmp_path / "elsewhere.svg").resolve())
