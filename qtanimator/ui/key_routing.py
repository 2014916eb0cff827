"""Letter keys go to the view under the mouse, never into a tree by accident.

Blender's rule: a view's one-letter keys (F frames, the 3D view's W/A/S/D, the rig editor's
D …) act on the editor under the mouse pointer. Here the focused editor keeps its keys, but a
letter typed while a tree or list has the focus (the outliner after a click on a row, the
curve editor's channel list) and the pointer is over a view (:data:`VIEWS`: the 2D rig
editor, the 3D view, the curve plot) goes to that view instead of moving the tree's current
row by type-ahead. :class:`ViewKeyRouter` is an application event filter doing that,
installed once by :func:`install_view_key_router`; the outliner also has no type-ahead at
all (its F frames the current row's asset, see
:meth:`qtanimator.ui.outliner_tree.JointTree.keyPressEvent`).
"""

from __future__ import annotations

from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtGui import QCursor, QKeyEvent
from PySide6.QtWidgets import QAbstractItemView, QApplication, QWidget

from qtanimator.ui.timeline import KEY_TARGETS
from qtanimator.ui.widgets import install_app_filter

#: The views (by object name) whose letter keys follow the mouse: the editors that also get
#: the timeline's keys.
VIEWS = KEY_TARGETS
#: Modifiers that make a key a command (Ctrl+A …) rather than a view's letter key.
COMMAND_MODIFIERS = (Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.AltModifier
                     | Qt.KeyboardModifier.MetaModifier)


def is_letter_key(event: QKeyEvent) -> bool:
    """A plain letter key (Shift allowed; no Ctrl, Alt or Meta)."""
    return (Qt.Key.Key_A <= event.key() <= Qt.Key.Key_Z
            and not event.modifiers() & COMMAND_MODIFIERS)


def view_under_mouse() -> QWidget | None:
    """The visible view (:data:`VIEWS`) under the mouse pointer, or None."""
    widget = QApplication.widgetAt(QCursor.pos())
    while widget is not None:
        if widget.objectName() in VIEWS and widget.isVisible():
            return widget
        widget = widget.parentWidget()
    return None


class ViewKeyRouter(QObject):
    """The application event filter of :mod:`qtanimator.ui.key_routing`."""

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if (event.type() == QEvent.Type.KeyPress and isinstance(watched, QAbstractItemView)
                and isinstance(event, QKeyEvent) and is_letter_key(event)
                and watched.state() != QAbstractItemView.State.EditingState):
            view = view_under_mouse()
            if view is not None and view is not watched:  # the focus stays in the tree
                QApplication.sendEvent(view, QKeyEvent(event.type(), event.key(), event.modifiers(), event.text(),
                                                       event.isAutoRepeat(), event.count()))
                event.accept()
                return True
        return False


def install_view_key_router(app: QApplication | None = None) -> ViewKeyRouter | None:
    """Install :class:`ViewKeyRouter` on the application (once; later calls return it)."""
    return install_app_filter(ViewKeyRouter, "qtanimatorViewKeyRouter", app)


__all__ = ["COMMAND_MODIFIERS", "VIEWS", "ViewKeyRouter", "install_view_key_router", "is_letter_key",
           "view_under_mouse"]
