"""A save killed at any moment (kill -9) leaves the old file or the new one, never a broken
one, and the next save removes the killed save's temporary file."""

from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

from qtanimator.formats.atomic import remove_stale_temporaries, write_atomic

SAVER = textwrap.dedent("""
    import json, sys
    from qtanimator.formats.atomic import write_atomic
    path = sys.argv[1]
    i = 0
    print("ready", flush=True)
    while True:
        i += 1
        # ~2 MB per version, so that a kill often lands in the middle of a write.
        write_atomic(path, json.dumps({"version": i, "keys": [i] * 400_000}).encode())
""")


def test_kill_9_during_saves_never_leaves_a_broken_file(tmp_path: Path) -> None:
    target = tmp_path / "project.qtanim"
    write_atomic(target, json.dumps({"version": 0, "keys": []}).encode())
    rng = random.Random(1234)
    versions = []
    for _ in range(12):
        proc = subprocess.Popen([sys.executable, "-c", SAVER, str(target)], stdout=subprocess.PIPE, text=True)
        assert proc.stdout is not None and proc.stdout.readline().strip() == "ready"
        time.sleep(rng.uniform(0.01, 0.3))  # when to strike: not an assertion on speed
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
        data = json.loads(target.read_bytes())  # never a half-written file
        assert data["keys"] == [data["version"]] * len(data["keys"])
        versions.append(data["version"])
    # Killed saves may leave temporaries; the next save removes every one of them.
    write_atomic(target, b"{}")
    assert [p.name for p in tmp_path.iterdir()] == ["project.qtanim"]


def test_a_running_saves_temporary_is_left_alone(tmp_path: Path) -> None:
    target = tmp_path / "a.qtanim"
    mine = tmp_path / f".a.qtanim.{os.getpid()}.x.tmp"
    mine.write_bytes(b"")
    dead = tmp_path / ".a.qtanim.999999999.y.tmp"
    dead.write_bytes(b"")
    other = tmp_path / ".b.qtanim.999999999.y.tmp"  # another file's temporary
    other.write_bytes(b"")
    assert remove_stale_temporaries(target) == [dead]
    assert mine.exists() and other.exists()
