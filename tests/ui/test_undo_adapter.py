"""The production QUndoStack adapter (``qtanimator.ui.undo``) against the Qt-free
``UndoStack`` (``qtanimator.document.commands``): the same pushes, gesture merges,
committed and aborted gestures, undos and redos on two equal documents give the same
document states, the same undo and redo texts and the same index after every step.

Both documents' change notifications are compared too (a committed gesture is recorded, not
done again). The two stacks are independent implementations of one contract (ARCHITECTURE: "the GUI uses
QUndoStack through qtanimator.ui.undo with the same semantics"), so each is the other's
reference; a few fixed sequences also check hand-written expected histories.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from PySide6.QtGui import QUndoStack

from qtanimator.core.channel import Key
from qtanimator.document import Document
from qtanimator.document.commands import Command, SetKeys, SetParameter, UndoStack
from qtanimator.document.gesture import Gesture
from qtanimator.ui.undo import push_command, record_command

CIDS = ("hero//x", "hero/arm/angle")
PATHS = ("render.width", "fps")


class Plain:
    """The Qt-free stack and its document."""

    def __init__(self) -> None:
        self.doc = Document()
        self.stack = UndoStack(self.doc)
        self.changes: list[Any] = []
        self.doc.subscribe(self.changes.append)

    def push(self, command: Command) -> None:
        self.stack.push(command)

    def record(self, command: Command) -> None:
        self.stack.record(command)

    def undo(self) -> None:
        self.stack.undo()

    def redo(self) -> None:
        self.stack.redo()

    def history(self) -> tuple[list[str], list[str]]:
        """(undo texts bottom to top, redo texts next first)."""
        return [c.text for c in self.stack.done], [c.text for c in reversed(self.stack.undone)]


class Qt:
    """QUndoStack through the production adapter, as ``EditorContext`` uses it."""

    def __init__(self) -> None:
        self.doc = Document()
        self.stack = QUndoStack()
        self.changes: list[Any] = []
        self.doc.subscribe(self.changes.append)

    def push(self, command: Command) -> None:
        push_command(self.stack, self.doc, command)

    def record(self, command: Command) -> None:
        record_command(self.stack, self.doc, command)

    def undo(self) -> None:
        self.stack.undo()

    def redo(self) -> None:
        self.stack.redo()

    def history(self) -> tuple[list[str], list[str]]:
        texts = [self.stack.text(i) for i in range(self.stack.count())]
        i = self.stack.index()
        return texts[:i], texts[i:]


# An operation builds its commands from the document it is applied to (as editors do).
Op = Callable[[Any], None]


def push_param(path: str, value: int, gesture: int | None) -> Op:
    def op(side: Any) -> None:
        side.push(SetParameter(side.doc, path, value, gesture=None if gesture is None else ("slider", gesture)))
    op.__name__ = f"param({path}={value}, g={gesture})"
    return op


def push_key(cid: str, frame: int, value: int, gesture: int | None) -> Op:
    def op(side: Any) -> None:
        side.push(SetKeys(side.doc, {cid: Key(frame / 24.0, float(value))}, text=f"Key {cid}",
                          gesture=None if gesture is None else ("drag", gesture)))
    op.__name__ = f"key({cid}@{frame}={value}, g={gesture})"
    return op


def gesture(moves: list[tuple[str, int, int]], commit: bool) -> Op:
    """A drag through the gesture protocol: each move keys from the document as it is now."""
    def op(side: Any) -> None:
        g = Gesture(side.doc, "Drag", side.record)
        for cid, frame, value in moves:
            g.update(SetKeys(side.doc, {cid: Key(frame / 24.0, float(value))}, text="move"))
        if commit:
            g.commit()
        else:
            g.abort()
    op.__name__ = f"gesture({moves}, {'commit' if commit else 'abort'})"
    return op


def undo(side: Any) -> None:
    side.undo()


def redo(side: Any) -> None:
    side.redo()


def run_both(ops: list[Op]) -> tuple[Plain, Qt]:
    plain, qt = Plain(), Qt()
    assert plain.doc.state() == qt.doc.state()
    for step, op in enumerate(ops):
        op(plain)
        op(qt)
        where = f"after step {step} ({getattr(op, '__name__', op)})"
        assert qt.doc.state() == plain.doc.state(), where
        # the same notifications: one per command done or undone, none for recording a
        # gesture that is already done
        assert [(sorted(c.channels), sorted(c.parameters)) for c in qt.changes] == \
            [(sorted(c.channels), sorted(c.parameters)) for c in plain.changes], where
        assert qt.history() == plain.history(), where
        assert qt.stack.index() == len(plain.stack.done), where
        assert qt.stack.count() == len(plain.stack.done) + len(plain.stack.undone), where
        assert qt.stack.canUndo() == bool(plain.stack.done) and qt.stack.canRedo() == bool(plain.stack.undone), where
    return plain, qt


# ---------------------------------------------------------------- fixed sequences

def test_discrete_pushes_undo_redo(qapp) -> None:  # type: ignore[no-untyped-def]
    plain, qt = run_both([push_param("fps", 30, None), push_param("fps", 25, None), push_key(CIDS[0], 0, 5, None),
                          undo, undo, redo])
    assert qt.history() == (["Set fps", "Set fps"], ["Key hero//x"])
    assert qt.doc.parameter("fps") == 25 and CIDS[0] not in qt.doc.channels


def test_a_gesture_of_pushes_merges_into_one_step_and_undoes_whole(qapp) -> None:  # type: ignore[no-untyped-def]
    start = Document().parameter("fps")
    plain, qt = run_both([push_param("fps", 10, 1), push_param("fps", 11, 1), push_param("fps", 12, 1)])
    assert qt.history() == (["Set fps"], []) and qt.doc.parameter("fps") == 12
    run_both([push_param("fps", 10, 1), push_param("fps", 11, 1), undo])
    plain, qt = run_both([push_param("fps", 10, 1), push_param("fps", 11, 1), undo])
    assert qt.doc.parameter("fps") == start


def test_a_gesture_that_returns_to_its_start_leaves_no_step(qapp) -> None:  # type: ignore[no-untyped-def]
    start = int(Document().parameter("fps"))
    plain, qt = run_both([push_param("fps", 30, None), push_param("fps", 40, 2), push_param("fps", 30, 2)])
    assert qt.history() == (["Set fps"], [])
    plain, qt = run_both([push_key(CIDS[1], 3, 1, 4), push_key(CIDS[1], 3, 2, 4), undo, redo,
                          push_param("fps", start, None)])  # a no-op: recorded nowhere
    assert qt.history() == (["Key hero/arm/angle"], [])


def test_committed_and_aborted_gestures(qapp) -> None:  # type: ignore[no-untyped-def]
    plain, qt = run_both([gesture([(CIDS[0], 0, 1), (CIDS[0], 0, 2), (CIDS[1], 5, 3)], True),
                          gesture([(CIDS[0], 0, 9)], False),
                          undo, redo, gesture([(CIDS[0], 0, 7), (CIDS[0], 0, 2)], True)])
    assert qt.history() == (["Drag"], [])
    assert qt.doc.channels[CIDS[0]].keys[0].value == 2.0


def test_a_no_op_push_after_an_undo_drops_the_redo_history_on_both(qapp) -> None:  # type: ignore[no-untyped-def]
    plain, qt = run_both([push_param("fps", 21, None), push_param("fps", 22, None), undo,
                          push_param("fps", 21, None)])
    assert plain.history() == (["Set fps"], [])


def test_a_no_op_push_with_the_gesture_token_of_another_command_is_not_a_step(qapp) -> None:  # type: ignore[no-untyped-def]
    plain, qt = run_both([push_param("render.width", 21, None), push_param("fps", 21, 1),
                          push_param("render.width", 21, 1)])
    assert plain.history() == (["Set render.width", "Set fps"], [])


# ---------------------------------------------------------------- random sequences

frames = st.integers(0, 3)
values = st.integers(-2, 2)
tokens = st.one_of(st.none(), st.integers(1, 2))
ops = st.one_of(
    # two values, so pushes that change nothing are common
    st.builds(push_param, st.sampled_from(PATHS), st.integers(21, 22), tokens),
    st.builds(push_key, st.sampled_from(CIDS), frames, values, tokens),
    st.builds(gesture, st.lists(st.tuples(st.sampled_from(CIDS), frames, values), max_size=3), st.booleans()),
    st.just(undo),
    st.just(redo),
)


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(ops, max_size=14))
def test_random_histories_agree(qapp, sequence: list[Op]) -> None:  # type: ignore[no-untyped-def]
    run_both(sequence)
