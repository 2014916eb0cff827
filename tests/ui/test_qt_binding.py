"""The Qt binding that is installed does not corrupt the interpreter (issue 30).

PySide6 6.12.0 on Python 3.11 dropped one reference to ``None`` on every method that returns
nothing; after enough calls the interpreter aborted ("Fatal Python error: none_dealloc"), seconds
into playback. pyproject.toml excludes that release; this test counts the references on whatever
PySide6 the environment has, so CI's newest-allowed job fails on the next release with the bug
before a user's pip picks it.
"""

from __future__ import annotations

import sys

import pytest


def _none_refs_after(calls: int, action) -> int:  # type: ignore[no-untyped-def]
    before = sys.getrefcount(None)
    for _ in range(calls):
        action()
    return sys.getrefcount(None) - before


@pytest.mark.parametrize("what", ["QPointF.setX", "QPainter.save/restore", "QTransform.reset"])
def test_void_methods_keep_the_reference_count_of_none(what: str, qapp) -> None:  # type: ignore[no-untyped-def]
    from PySide6.QtCore import QPointF
    from PySide6.QtGui import QImage, QPainter, QTransform

    if what == "QPointF.setX":
        point = QPointF(0.0, 0.0)
        action = lambda: point.setX(1.0)  # noqa: E731
    elif what == "QPainter.save/restore":
        image = QImage(4, 4, QImage.Format.Format_ARGB32)
        painter = QPainter(image)

        def action() -> None:
            painter.save()
            painter.restore()
    else:
        transform = QTransform()
        action = transform.reset
    _none_refs_after(10, action)  # warm up: caches, interned results
    drift = _none_refs_after(1000, action)
    if what == "QPainter.save/restore":
        painter.end()
    # 0 on a sound binding; -1000 (or -2000) on PySide6 6.12.0 with Python 3.11. A few references
    # either way may come from the interpreter itself (frames, the garbage collector).
    assert abs(drift) < 50, f"{what}: sys.getrefcount(None) moved by {drift} over 1000 calls"
