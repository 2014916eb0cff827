"""Any sequence of commands, undone, restores the document exactly; redone, reaches the end.

A hypothesis state machine drives the Qt-free UndoStack with every command type, with and
without gestures, interleaving undo and redo. It also checks each change event's
``time_from``: evaluation before that time must not have changed.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, invariant, precondition, rule
from hypothesis_profiles import thorough

from qtanimator.core.channel import Channel, Extrapolation, Key, Tangent
from qtanimator.document import (
    AddAsset,
    Asset,
    DeleteKeys,
    Document,
    DocumentChange,
    EditKey,
    InsertKey,
    Macro,
    MoveKeys,
    RemoveAsset,
    SetAssetProperty,
    SetExtrapolation,
    SetKeys,
    SetParameter,
    SetTangents,
    UndoStack,
)
from qtanimator.document.commands import Command
from qtanimator.document.gesture import Gesture

ASSETS = ["hero", "prop", "cam"]
CIDS = ["hero//x", "hero/arm/rz", "hero/arm/ry", "prop//y", "cam//fov"]
times = st.integers(0, 16).map(lambda i: i * 0.25)
values = st.integers(-8, 8).map(lambda i: i * 0.5)
rules = st.sampled_from(["flat", "linear", "smooth", "clamped", 1.5, -0.5])
modes = st.sampled_from(list(Extrapolation))
gestures = st.one_of(st.none(), st.sampled_from(["g1", "g2"]))
PROBE = np.linspace(-6.0, 10.0, 161)


@st.composite
def keys(draw: st.DrawFn) -> Key:
    return Key.make(draw(times), draw(values), draw(rules), draw(rules),
                    interpolation=draw(st.sampled_from(["cubic", "linear", "constant"])))


class CommandMachine(RuleBasedStateMachine):
    def __init__(self) -> None:
        super().__init__()
        self.doc = Document()
        self.stack = UndoStack(self.doc)
        self.states = [self.doc.state()]  # states[i]: after i recorded steps
        self.shadow: dict[str, Channel] = {}
        self.notifications = 0
        self.doc.subscribe(self.on_event)

    # -------------------------------------------------------------- bookkeeping
    def on_event(self, change: DocumentChange) -> None:
        assert change and not change.reset
        self.notifications += 1
        for cid, time_from in change.channels.items():
            old = self.shadow.get(cid)
            new = self.doc.channels.get(cid)
            if old is not None and new is not None and time_from > -math.inf:
                early = PROBE[PROBE < time_from]
                assert np.array_equal(old.evaluate(early), new.evaluate(early)), (cid, time_from)
            if new is None:
                self.shadow.pop(cid, None)
            else:
                self.shadow[cid] = new

    def one_notification(self, action: Callable[[], object]) -> None:
        """Run ``action``: however many channels it touches, at most one notification."""
        before = self.notifications
        action()
        assert self.notifications - before <= 1

    def push(self, cmd: Command) -> None:
        self.one_notification(lambda: self.stack.push(cmd))
        n = len(self.stack.done)
        self.states = self.states[:n] + [self.doc.state()]
        assert not self.stack.undone

    def channel_ids(self) -> list[str]:
        return sorted(self.doc.channels)

    # --------------------------------------------------------------------- rules
    @rule(cid=st.sampled_from(CIDS), key=keys(), gesture=gestures)
    def insert_key(self, cid: str, key: Key, gesture: str | None) -> None:
        self.push(InsertKey(self.doc, cid, key, gesture=gesture))

    @rule(items=st.dictionaries(st.sampled_from(CIDS), keys(), min_size=1, max_size=3))
    def set_keys(self, items: dict[str, Key]) -> None:
        self.push(SetKeys(self.doc, items))

    @precondition(lambda self: self.doc.channels)
    @rule(data=st.data())
    def delete_keys(self, data: st.DataObject) -> None:
        cid = data.draw(st.sampled_from(self.channel_ids()))
        n = len(self.doc.channels[cid].keys)
        idx = data.draw(st.sets(st.integers(0, max(n - 1, 0)), max_size=3))
        self.push(DeleteKeys(self.doc, {cid: idx}))

    @precondition(lambda self: any(self.doc.channels.values()))
    @rule(data=st.data(), gesture=gestures)
    def move_keys(self, data: st.DataObject, gesture: str | None) -> None:
        cid = data.draw(st.sampled_from([c for c in self.channel_ids() if self.doc.channels[c].keys]))
        n = len(self.doc.channels[cid].keys)
        idx = sorted(data.draw(st.sets(st.integers(0, n - 1), min_size=1, max_size=n)))
        base = dict(self.doc.channels)
        # One drag: several mouse moves built from the same base, at most one undo step.
        steps_before = len(self.stack.done)
        # Without a gesture token every command is its own step, so a command must be
        # built from the document as it is: one move only.
        moves = data.draw(st.lists(st.tuples(times, values), min_size=1, max_size=3 if gesture else 1))
        for dt, dv in moves:
            try:
                cmd = MoveKeys(base, {cid: idx}, dt - 2.0, dv, gesture=gesture)
            except ValueError:  # a key would land on another: nothing happens
                assert self.doc.state() == self.states[len(self.stack.done)]
                continue
            self.push(cmd)
        if gesture is not None:
            assert len(self.stack.done) <= steps_before + 1

    @precondition(lambda self: any(self.doc.channels.values()))
    @rule(data=st.data(), key=keys(), gesture=gestures)
    def edit_key(self, data: st.DataObject, key: Key, gesture: str | None) -> None:
        cid = data.draw(st.sampled_from([c for c in self.channel_ids() if self.doc.channels[c].keys]))
        i = data.draw(st.integers(0, len(self.doc.channels[cid].keys) - 1))
        try:
            cmd = EditKey(self.doc, cid, i, key, gesture=gesture)
        except ValueError:
            return
        self.push(cmd)

    @precondition(lambda self: any(self.doc.channels.values()))
    @rule(data=st.data(), rule_=st.sampled_from(list(Tangent)), side=st.sampled_from(["in", "out", "both"]))
    def set_tangents(self, data: st.DataObject, rule_: Tangent, side: str) -> None:
        cid = data.draw(st.sampled_from([c for c in self.channel_ids() if self.doc.channels[c].keys]))
        n = len(self.doc.channels[cid].keys)
        idx = data.draw(st.sets(st.integers(0, n - 1), min_size=1))
        self.push(SetTangents(self.doc, {cid: idx}, rule_, side))

    @precondition(lambda self: self.doc.channels)
    @rule(data=st.data(), pre=st.one_of(st.none(), modes), post=st.one_of(st.none(), modes))
    def set_extrapolation(self, data: st.DataObject, pre: Extrapolation | None, post: Extrapolation | None) -> None:
        cids = data.draw(st.sets(st.sampled_from(self.channel_ids()), min_size=1))
        self.push(SetExtrapolation(self.doc, cids, pre, post))

    @rule(path=st.sampled_from(["fps", "frame_end", "cloth.wind", "light1.color"]),
          value=st.one_of(st.integers(1, 120), st.floats(0.5, 99), st.lists(st.floats(0, 1), max_size=3)),
          gesture=gestures)
    def set_parameter(self, path: str, value: object, gesture: str | None) -> None:
        try:
            cmd = SetParameter(self.doc, path, value, gesture=gesture)
        except ValueError:  # a value the parameter schema refuses (fps as a list…)
            return
        self.push(cmd)

    @rule(path=st.sampled_from(["cloth.wind", "light1.color"]))
    def remove_parameter(self, path: str) -> None:
        self.push(SetParameter(self.doc, path, None))

    @rule(aid=st.sampled_from(ASSETS), kind=st.sampled_from(["character2d", "light"]),
          props=st.dictionaries(st.sampled_from(["scale", "color"]), st.integers(0, 9), max_size=2),
          chans=st.dictionaries(st.sampled_from(["x", "y"]), keys(), max_size=2))
    def add_asset(self, aid: str, kind: str, props: dict[str, int], chans: dict[str, Key]) -> None:
        channels = {f"{aid}//{dof}": Channel([k]) for dof, k in chans.items()}
        self.push(AddAsset(Asset(aid, kind, None, props), runtime=object(), channels=channels))

    @precondition(lambda self: self.doc.assets)
    @rule(data=st.data())
    def remove_asset(self, data: st.DataObject) -> None:
        aid = data.draw(st.sampled_from(sorted(self.doc.assets)))
        self.push(RemoveAsset(self.doc, aid))

    @precondition(lambda self: self.doc.assets)
    @rule(data=st.data(), value=st.one_of(st.none(), st.integers(0, 9)), gesture=gestures)
    def set_asset_property(self, data: st.DataObject, value: int | None, gesture: str | None) -> None:
        aid = data.draw(st.sampled_from(sorted(self.doc.assets)))
        self.push(SetAssetProperty(self.doc, aid, "scale", value, gesture=gesture))

    @rule(a=st.sampled_from(CIDS), ka=keys(), b=st.sampled_from(CIDS), kb=keys(), gesture=gestures)
    def macro(self, a: str, ka: Key, b: str, kb: Key, gesture: str | None) -> None:
        first = InsertKey(self.doc, a, ka, gesture=gesture)
        first.do(self.doc)  # build the second command on top of the first, as editors do
        second = InsertKey(self.doc, b, kb, gesture=gesture)
        first.undo(self.doc)
        self.push(Macro("Two keys", [first, second], gesture=gesture))

    @precondition(lambda self: any(self.doc.channels.values()))
    @rule(data=st.data(), commit=st.booleans())
    def gesture(self, data: st.DataObject, commit: bool) -> None:
        """A drag through the gesture protocol: previews, then one step or nothing."""
        before = self.doc.state()
        steps_before = len(self.stack.done)
        gesture = Gesture(self.doc, "Drag", self.stack.record)
        for key in data.draw(st.lists(keys(), min_size=1, max_size=4)):
            cid = data.draw(st.sampled_from(CIDS))
            self.one_notification(lambda c=cid, k=key: gesture.update(InsertKey(self.doc, c, k)))
        if not commit:
            gesture.abort()
            assert self.doc.state() == before and len(self.stack.done) == steps_before
            return
        recorded = gesture.commit()
        assert len(self.stack.done) == steps_before + (recorded is not None)
        assert not self.stack.undone
        if recorded is None:
            assert self.doc.state() == before
        self.states = self.states[:len(self.stack.done)] + [self.doc.state()]

    @rule()
    def undo(self) -> None:
        could = bool(self.stack.done)
        self.one_notification(lambda: self.stack.undo() == could or pytest.fail("undo"))
        assert self.doc.state() == self.states[len(self.stack.done)]

    @rule()
    def redo(self) -> None:
        self.one_notification(self.stack.redo)
        assert self.doc.state() == self.states[len(self.stack.done)]

    # ---------------------------------------------------------------- invariants
    @invariant()
    def history_matches(self) -> None:
        assert len(self.states) == len(self.stack.done) + len(self.stack.undone) + 1
        assert self.doc.state() == self.states[len(self.stack.done)]
        assert set(self.shadow) == set(self.doc.channels)

    def teardown(self) -> None:
        while self.stack.undo():
            pass
        assert self.doc.state() == self.states[0]
        assert self.doc.state() == Document().state()
        while self.stack.redo():
            pass
        assert self.doc.state() == self.states[-1]


# 100 sequences locally, 200 with fixed seeds in CI (tests/hypothesis_profiles.py): about
# 10 s on one core in CI, hence the slow mark.
CommandMachine.TestCase.settings = thorough(
    max_examples=max(100, thorough().max_examples), stateful_step_count=30, deadline=None)
TestCommands = pytest.mark.slow(CommandMachine.TestCase)
