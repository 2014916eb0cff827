"""Saving on a worker thread: snapshots, superseding, discarding (no Qt, no clocks).

The writer is swapped for one that records which thread called it and, where a test needs
the worker to stand still, waits on an Event the test sets. Every wait has a timeout, so a
broken implementation fails instead of hanging.
"""

from __future__ import annotations

import threading
from collections.abc import Iterable
from pathlib import Path

import pytest
from docfix import set_channels, set_parameters

from qtanimator.core.channel import Channel, Key
from qtanimator.document import AddAsset, Asset, Document, InsertKey, SetAssetProperty, SetParameter, UndoStack
from qtanimator.document.background_save import BackgroundSaver, same_snapshot
from qtanimator.document.io import open_document, to_project_data
from qtanimator.formats.atomic import write_chunks_atomic
from qtanimator.formats.project import project_to_json

WAIT = 10.0  # seconds a test waits for the worker before it fails (never reached when all is well)


class HeldWriter:
    """A file writer whose calls for ``hold`` wait until :meth:`release`."""

    def __init__(self, hold: Path | None = None) -> None:
        self.hold = hold
        self.entered = threading.Event()
        self.released = threading.Event()
        self.calls: list[tuple[Path, threading.Thread]] = []  # (path, the thread that wrote it)

    def __call__(self, path: Path, chunks: Iterable[bytes]) -> None:
        self.calls.append((path, threading.current_thread()))
        if path == self.hold:
            self.entered.set()
            if not self.released.wait(WAIT):
                raise OSError("the test never released the writer")
        write_chunks_atomic(path, chunks)

    def release(self) -> None:
        self.released.set()


def make_doc() -> tuple[Document, UndoStack]:
    doc = Document()
    stack = UndoStack(doc)
    stack.push(AddAsset(Asset("lamp", "light", None, {"intensity": 0.5, "tags": ["a"]})))
    for i in range(50):
        stack.push(InsertKey(doc, f"lamp/j{i % 5}/rz", Key(i / 60.0, i * 0.1)))
    stack.push(SetParameter(doc, "cloth.wind", {"speed": 1.5}))
    return doc, stack


@pytest.fixture
def saver():
    s = BackgroundSaver()
    yield s
    s.shutdown()


def test_the_worker_writes_what_the_snapshot_held(tmp_path, saver):
    doc, stack = make_doc()
    path = tmp_path / "a.qtanim"
    writer = HeldWriter(hold=path)
    saver.write_file = writer
    data = to_project_data(doc)
    expected_text = project_to_json(data, tmp_path)
    expected_state = doc.state()
    job = saver.submit(data, path, [(tmp_path / "a.json", b"{}")])
    # submit returned although the worker cannot finish: it runs elsewhere.
    assert writer.entered.wait(WAIT)
    assert saver.busy and not job.done and not path.exists()
    # Edits after the snapshot change the document, not what is being written.
    stack.push(InsertKey(doc, "lamp/j0/rz", Key(0.0, 99.0)))
    stack.push(SetAssetProperty(doc, "lamp", "intensity", 2.0))
    stack.push(SetParameter(doc, "cloth.wind", {"speed": 3.0}))
    writer.release()
    assert job.wait(WAIT)
    assert not saver.busy and saver.collect() == [job] and saver.collect() == []
    assert job.written and job.error is None
    (thread,) = {t for _, t in writer.calls}
    assert thread is not threading.current_thread() and thread.name.startswith("qtanimator-save")
    assert [p for p, _ in writer.calls] == [path, tmp_path / "a.json"]
    assert path.read_text(encoding="utf-8") == expected_text
    assert open_document(path).state() == expected_state != doc.state()


def test_a_newer_save_supersedes_the_ones_in_flight(tmp_path, saver):
    doc, stack = make_doc()
    path = tmp_path / "a.qtanim"
    old = b"the previous save"
    path.write_bytes(old)
    writer = HeldWriter(hold=path)
    saver.write_file = writer
    first = saver.submit(to_project_data(doc), path)
    assert writer.entered.wait(WAIT)  # the first has begun writing its temporary file
    stack.push(InsertKey(doc, "lamp/j1/rz", Key(5.0, 1.0)))
    second = saver.submit(to_project_data(doc), path)  # queued behind the first ...
    stack.push(InsertKey(doc, "lamp/j2/rz", Key(6.0, 2.0)))
    third = saver.submit(to_project_data(doc), path)  # ... and superseded by this one
    assert first.superseded and second.superseded and not third.superseded
    assert path.read_bytes() == old
    writer.release()
    assert third.wait(WAIT)
    # The first stopped between two channels and left the old file; the second never began.
    assert not first.wait(WAIT) and not second.wait(WAIT)
    assert first.error is None and second.error is None
    assert [p for p, _ in writer.calls] == [path, path]
    assert open_document(path).state() == doc.state()
    assert saver.collect() == [first, second, third]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.qtanim"]  # no temporary file left


def test_discard_stops_a_job_and_removes_what_it_still_writes(tmp_path, saver):
    doc, _stack = make_doc()
    path, note = tmp_path / "a.qtanim", tmp_path / "a.json"
    # Held inside the project file's write: the discard stops it there.
    writer = HeldWriter(hold=path)
    saver.write_file = writer
    job = saver.submit(to_project_data(doc), path, [(note, b"{}")])
    assert writer.entered.wait(WAIT)
    queued = saver.submit(to_project_data(doc), path, [(note, b"{}")])
    saver.discard()  # returns at once although the worker is inside the write
    assert not job.done
    writer.release()
    assert not job.wait(WAIT) and not queued.wait(WAIT)
    assert job.discarded and not job.written and job.error is None
    assert sorted(tmp_path.iterdir()) == []  # no temporary file left either
    # Held while writing the note, after the project file is in place: too late to stop,
    # so the job removes both files itself once it has written them.
    writer = HeldWriter(hold=note)
    saver.write_file = writer
    job = saver.submit(to_project_data(doc), path, [(note, b"{}")])
    assert writer.entered.wait(WAIT)
    assert path.is_file()
    saver.discard()
    for p in (path, note):  # what the caller of discard() does
        p.unlink(missing_ok=True)
    writer.release()
    assert not job.wait(WAIT)
    assert not job.written and job.error is None
    assert sorted(tmp_path.iterdir()) == []


def test_a_failed_write_is_reported_on_the_job(tmp_path, saver):
    doc, _stack = make_doc()

    def broken(path: Path, chunks: Iterable[bytes]) -> None:
        raise OSError(28, "No space left on device")

    saver.write_file = broken
    job = saver.submit(to_project_data(doc), tmp_path / "a.qtanim")
    assert not job.wait(WAIT)
    assert isinstance(job.error, OSError) and not job.written
    set_parameters(doc, {"bad": object()})
    saver.write_file = write_chunks_atomic
    job = saver.submit(to_project_data(doc), tmp_path / "a.qtanim")
    assert not job.wait(WAIT)
    assert isinstance(job.error, ValueError) and not (tmp_path / "a.qtanim").exists()


def test_a_shut_down_saver_takes_no_more_jobs(tmp_path):
    saver = BackgroundSaver()
    saver.shutdown()
    with pytest.raises(RuntimeError):
        saver.submit(to_project_data(Document()), tmp_path / "a.qtanim")


def test_same_snapshot_compares_channels_by_identity_and_the_rest_by_value():
    doc, stack = make_doc()
    a = to_project_data(doc)
    assert same_snapshot(a, to_project_data(doc))
    assert a.channels is not doc.channels and a.parameters["cloth.wind"] is not doc.parameters["cloth.wind"]
    # An equal but new channel object counts as a change (a snapshot never compares keys).
    set_channels(doc, {"lamp/j0/rz": Channel(doc.channels["lamp/j0/rz"].keys)})
    assert not same_snapshot(a, to_project_data(doc))
    b = to_project_data(doc)
    stack.push(SetParameter(doc, "fps", 30))
    assert not same_snapshot(b, to_project_data(doc))
    c = to_project_data(doc)
    stack.push(SetAssetProperty(doc, "lamp", "tags", ["a", "b"]))
    assert not same_snapshot(c, to_project_data(doc))
    d = to_project_data(doc)
    doc.set_view_state("view3d.camera", {"azimuth": 1.0})
    assert not same_snapshot(d, to_project_data(doc))
