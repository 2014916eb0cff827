"""Setting up a test document's channels and parameters: through commands, as editors do.

``Document.channels`` and ``Document.parameters`` are read-only views; a fixture writes them
with these (each runs one command on the document, in one batch, without an undo stack)::

    from docfix import set_channels, set_parameters

    set_channels(doc, {"hero//x": Channel([Key(0.0, 0.0), Key(1.0, 2.0)])})
    set_parameters(doc, frame_start=5, frame_end=65)
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from qtanimator.core.channel import Channel
from qtanimator.document import Document
from qtanimator.document.commands import Command, Macro, SetChannels, SetParameter


def run(doc: Document, command: Command) -> None:
    """Do ``command`` on ``doc`` as one change (no undo step)."""
    with doc.batch():
        command.do(doc)


def set_channels(doc: Document, channels: Mapping[str, Channel | None]) -> None:
    """Set (or with None remove) channels of ``doc`` by one ``SetChannels``."""
    run(doc, SetChannels("Set up", {cid: (doc.channels.get(cid), ch) for cid, ch in channels.items()}))


def set_parameters(doc: Document, values: Mapping[str, Any] | None = None, **kw: Any) -> None:
    """Set (or with None remove) parameters of ``doc``: ``set_parameters(doc, fps=24)`` or
    ``set_parameters(doc, {"cloth1.wind.speed": 2.0})`` (dotted paths), by ``SetParameter``s."""
    items = {**(values or {}), **kw}
    run(doc, Macro("Set up", [SetParameter(doc, path, value) for path, value in items.items()]))
