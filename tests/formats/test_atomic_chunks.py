"""Streamed atomic writes: the same promises as formats.atomic, with data in pieces."""

from __future__ import annotations

import os
import stat
from collections.abc import Iterator
from pathlib import Path

import pytest

from qtanimator.formats.atomic import write_chunks_atomic


def test_chunks_are_written_in_order_and_swapped_in(tmp_path: Path) -> None:
    target = tmp_path / "a.qtanim"
    write_chunks_atomic(target, (bytes([65 + i]) * 3 for i in range(4)))
    assert target.read_bytes() == b"AAABBBCCCDDD"
    write_chunks_atomic(target, [])
    assert target.read_bytes() == b""
    assert [p.name for p in tmp_path.iterdir()] == ["a.qtanim"]


def test_a_failing_stream_leaves_the_old_file_and_no_temporary(tmp_path: Path) -> None:
    target = tmp_path / "a.qtanim"
    target.write_bytes(b"old")

    def pieces() -> Iterator[bytes]:
        yield b"new, half"
        raise ValueError("the project holds a value JSON cannot store")

    with pytest.raises(ValueError):
        write_chunks_atomic(target, pieces())
    assert target.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["a.qtanim"]


@pytest.mark.skipif(os.name != "posix", reason="POSIX file modes and process ids")
def test_mode_is_kept_and_stale_temporaries_go(tmp_path: Path) -> None:
    target = tmp_path / "a.qtanim"
    target.write_bytes(b"old")
    target.chmod(0o640)
    dead = tmp_path / ".a.qtanim.999999999.x.tmp"  # a killed save's leftover
    dead.write_bytes(b"")
    write_chunks_atomic(target, [b"new"])
    assert stat.S_IMODE(target.stat().st_mode) == 0o640
    assert [p.name for p in tmp_path.iterdir()] == ["a.qtanim"]
