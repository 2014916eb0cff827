"""How every field of the program behaves, in one place (issue 13, item 5).

* :class:`DockBehaviour` is one application-wide event filter (:func:`install_dock_behaviour`,
  called by the main window):

  - the wheel over a spin box, a slider or a combo box that does not have the keyboard
    focus changes nothing: it scrolls what holds the field (a dock's scroll area), as if
    the field were not there. A focused field still takes the wheel. Such fields take the
    focus by click or Tab, never by the wheel.
  - Undo / Redo (Ctrl+Z, Ctrl+Shift+Z, Ctrl+Y) undo the *document* whatever has the focus,
    except while a text field is being edited with text not yet entered: a spin box whose
    text differs from its value, a line edit typed in since it was last entered. Then the
    field's own undo takes the keys, as in every text editor.

* :class:`CheckedDoubleSpinBox` / :class:`CheckedSpinBox` never clamp a typed value in
  silence: a number outside the field's range is refused with the reason shown (the field
  turns red, its tool tip and the window's status bar say why) and the field keeps its
  value. The range of a field is the range its parameter accepts (the parameter
  definitions: :mod:`qtanimator.core.cloth`, :mod:`qtanimator.core.pendulum`, the lights);
  where any value is physically fine the range is wide.
"""

from __future__ import annotations

import math
from typing import Any, TypeVar

from PySide6.QtCore import QEvent, QObject, QPointF, Qt, Signal
from PySide6.QtGui import QKeyEvent, QKeySequence, QValidator, QWheelEvent
from PySide6.QtWidgets import (
    QAbstractScrollArea,
    QAbstractSlider,
    QAbstractSpinBox,
    QApplication,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QLineEdit,
    QMainWindow,
    QScrollBar,
    QSpinBox,
    QWidget,
)

#: How long a refusal stays in the status bar (ms).
STATUS_MS = 8000
_REFUSED_STYLE = "background-color: #7a2a2a; color: white;"


# --------------------------------------------------------------------- the wheel
def takes_wheel_only_when_focused(widget: object) -> bool:
    """Fields whose value the wheel would change: spin boxes, sliders (not scroll bars),
    combo boxes."""
    if isinstance(widget, QScrollBar):
        return False
    return isinstance(widget, (QAbstractSpinBox, QAbstractSlider, QComboBox))


def _pass_wheel_on(field: QWidget, event: QWheelEvent) -> None:
    """Give the wheel to what holds ``field``, as if the field were not there: the first
    ancestor that accepts it (a scroll area's viewport scrolls)."""
    pos = event.position()
    w: QWidget | None = field
    while w is not None and not w.isWindow():
        pos = QPointF(w.mapToParent(pos))
        w = w.parentWidget()
        if w is None:
            return
        if takes_wheel_only_when_focused(w) and not w.hasFocus():
            continue
        copy = QWheelEvent(pos, event.globalPosition(), event.pixelDelta(), event.angleDelta(), event.buttons(),
                           event.modifiers(), event.phase(), event.inverted(), event.source())
        copy.setAccepted(False)
        target: QWidget = w
        if isinstance(w, QAbstractScrollArea):
            target = w.viewport()
        QApplication.sendEvent(target, copy)
        if copy.isAccepted():
            return


# ------------------------------------------------------------------------- undo
UNDO_KEYS = (QKeySequence.StandardKey.Undo, QKeySequence.StandardKey.Redo)
_CTRL_Y = QKeySequence("Ctrl+Y")


def is_undo_key(event: QKeyEvent) -> bool:
    if any(event.matches(k) for k in UNDO_KEYS):
        return True
    combo = event.keyCombination()
    return QKeySequence(combo) == _CTRL_Y


def text_being_edited(widget: QObject) -> bool:
    """True while ``widget`` (or the spin box that owns it) holds typed text not yet entered."""
    spin = widget if isinstance(widget, QAbstractSpinBox) else widget.parent()
    if isinstance(spin, (QSpinBox, QDoubleSpinBox)):
        if spin.isReadOnly():
            return False
        if spin.specialValueText() and spin.value() == spin.minimum():
            shown = spin.specialValueText()
        else:
            shown = spin.prefix() + spin.textFromValue(spin.value()) + spin.suffix()  # type: ignore[arg-type]
        return spin.text() != shown
    if isinstance(widget, QLineEdit):
        return not widget.isReadOnly() and widget.isModified() and (
            widget.isUndoAvailable() or widget.isRedoAvailable())
    return False


class DockBehaviour(QObject):
    """The application-wide event filter (see the module's description)."""

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        kind = event.type()
        if kind == QEvent.Type.Wheel:
            # (Over a spin box's text the wheel reaches the box: its line edit ignores it.)
            if isinstance(watched, QWidget) and takes_wheel_only_when_focused(watched) and not watched.hasFocus():
                _pass_wheel_on(watched, event)  # type: ignore[arg-type]
                event.accept()
                return True
        elif kind == QEvent.Type.ShortcutOverride:
            # A text field claims Ctrl+Z for its own undo; let the window's Undo have it
            # unless the field is being edited.
            if isinstance(watched, QWidget) and is_undo_key(event) and not text_being_edited(watched):  # type: ignore[arg-type]
                event.ignore()
                return True
        elif kind == QEvent.Type.Polish:
            if isinstance(watched, QWidget) and takes_wheel_only_when_focused(watched):
                if watched.focusPolicy() == Qt.FocusPolicy.WheelFocus:
                    watched.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        elif kind == QEvent.Type.FocusIn and isinstance(watched, QLineEdit) \
                and not isinstance(watched.parent(), QAbstractSpinBox):
            # Entering a line edit's text ends its edit: Ctrl+Z then undoes the document.
            if not watched.property("qtanimatorEditEnds"):
                watched.setProperty("qtanimatorEditEnds", True)
                watched.editingFinished.connect(lambda le=watched: le.setModified(False))
        return False


FilterT = TypeVar("FilterT", bound=QObject)


def install_app_filter(kind: type[FilterT], name: str, app: QApplication | None = None) -> FilterT | None:
    """Install one event filter of ``kind`` (a QObject made with the application as its
    parent) on the whole application, once: later calls return the one named ``name``."""
    app = app or QApplication.instance()  # type: ignore[assignment]
    if app is None:
        return None
    existing = app.findChild(kind, name)
    if existing is not None:
        return existing
    installed = kind(app)
    installed.setObjectName(name)
    app.installEventFilter(installed)
    return installed


def install_dock_behaviour(app: QApplication | None = None) -> DockBehaviour | None:
    """Install :class:`DockBehaviour` on the application (once; later calls return it)."""
    return install_app_filter(DockBehaviour, "qtanimatorDockBehaviour", app)


def wrap_long_rows(widget: QWidget) -> None:
    """Let every form under ``widget`` put a field below its label when the row does not
    fit (QFormLayout.WrapLongRows): a dock's form then needs the width of its widest label
    or field, not of both side by side, and the dock can be narrow (a laptop screen)."""
    for form in widget.findChildren(QFormLayout):
        form.setRowWrapPolicy(QFormLayout.RowWrapPolicy.WrapLongRows)


# --------------------------------------------------------------- checked fields
def _number_text(box: QAbstractSpinBox, text: str) -> str:
    t = text
    prefix, suffix = box.prefix(), box.suffix()  # type: ignore[attr-defined]
    if prefix and t.startswith(prefix):
        t = t[len(prefix):]
    if suffix and t.endswith(suffix):
        t = t[: -len(suffix)]
    return t.strip()


def format_number(value: float) -> str:
    return f"{value:.6g}"


class _Checked:
    """What both checked spin boxes share: typed numbers outside the range are refused
    with a reason, never clamped."""

    #: Emitted with the reason when a typed value is refused.
    refused: Any
    #: A label for messages ("Stiffness"); the object name otherwise.
    label: str = ""
    #: Why the field stops at its maximum where the parameter itself does not (shown).
    why_max: str = ""

    def _init_checked(self) -> None:
        self._tip: str | None = None
        self.last_refusal = ""
        # Not on every text change: the field puts its value back right after a refusal.
        self.lineEdit().textEdited.connect(self._clear_refusal)  # type: ignore[attr-defined]
        self.valueChanged.connect(self._clear_refusal)  # type: ignore[attr-defined]

    def _parse(self, text: str) -> float | None:
        t = _number_text(self, text)  # type: ignore[arg-type]
        value, ok = self.locale().toDouble(t)  # type: ignore[attr-defined]
        if not ok:
            try:
                value = float(t)
            except ValueError:
                return None
        return value if math.isfinite(value) else None

    def _check_validate(self, result: Any, text: str, pos: int) -> Any:
        state = result[0] if isinstance(result, tuple) else result
        if state != QValidator.State.Invalid:
            return result
        t = _number_text(self, text)  # type: ignore[arg-type]
        value = self._parse(text)
        lo, hi = self.minimum(), self.maximum()  # type: ignore[attr-defined]
        if value is not None and not (lo <= value <= hi):
            return (QValidator.State.Intermediate, text, pos)  # typed: refused (or not) on Enter
        if t in ("-", "+", ".", "-.", "+.") and lo < 0:
            return (QValidator.State.Intermediate, text, pos)
        if t in ("-", "-.") and lo >= 0:
            return (QValidator.State.Intermediate, text, pos)  # refused with a reason on Enter
        return result

    def _check_fixup(self, text: str) -> None:
        value = self._parse(text)
        lo, hi = self.minimum(), self.maximum()  # type: ignore[attr-defined]
        if value is None:
            if _number_text(self, text) in ("-", "-.") and lo >= 0:  # type: ignore[arg-type]
                self.refuse(f"{self._name()} cannot be negative (the smallest value is {format_number(lo)}).")
            return
        if value < lo:
            self.refuse(f"{self._name()}: {format_number(value)} is below the smallest value, {format_number(lo)}.")
        elif value > hi:
            why = f" ({self.why_max})" if self.why_max else ""
            self.refuse(f"{self._name()}: {format_number(value)} is above the largest value, "
                        f"{format_number(hi)}{why}.")

    def _name(self) -> str:
        if self.label:
            return self.label
        name = self.objectName() or "This field"  # type: ignore[attr-defined]
        return name.split("_", 1)[-1].replace("_", " ").capitalize() if "_" in name else name

    def refuse(self, reason: str) -> None:
        """Refuse what was typed: keep the value, turn red, say why (tool tip, status bar)."""
        w: QWidget = self  # type: ignore[assignment]
        self.last_refusal = reason
        if self._tip is None:
            self._tip = w.toolTip()
        w.setStyleSheet(_REFUSED_STYLE)
        w.setToolTip(reason)
        window = w.window()
        if isinstance(window, QMainWindow):
            window.statusBar().showMessage(reason, STATUS_MS)
        self.refused.emit(reason)

    def _clear_refusal(self, *_args: object) -> None:
        """Typing again, or a value accepted, ends the refusal's red."""
        if self._tip is not None:
            w: QWidget = self  # type: ignore[assignment]
            w.setStyleSheet("")
            w.setToolTip(self._tip)
            self._tip = None

    @property
    def refusing(self) -> bool:
        """True while the field shows a refusal (red)."""
        return self._tip is not None


class CheckedDoubleSpinBox(_Checked, QDoubleSpinBox):
    """A QDoubleSpinBox that refuses, with a reason, typed values outside its range."""

    refused = Signal(str)

    def __init__(self, parent: QWidget | None = None, label: str = "") -> None:
        super().__init__(parent)
        self.label = label
        self._init_checked()

    def validate(self, text: str, pos: int) -> object:
        return self._check_validate(super().validate(text, pos), text, pos)

    def fixup(self, text: str) -> str:
        self._check_fixup(text)
        return super().fixup(text)


class CheckedSpinBox(_Checked, QSpinBox):
    """A QSpinBox that refuses, with a reason, typed values outside its range."""

    refused = Signal(str)

    def __init__(self, parent: QWidget | None = None, label: str = "") -> None:
        super().__init__(parent)
        self.label = label
        self._init_checked()

    def _parse(self, text: str) -> float | None:
        t = _number_text(self, text)
        try:
            return float(int(t))
        except ValueError:
            return None

    def validate(self, text: str, pos: int) -> object:
        return self._check_validate(super().validate(text, pos), text, pos)

    def fixup(self, text: str) -> str:
        self._check_fixup(text)
        return super().fixup(text)


__all__ = [
    "CheckedDoubleSpinBox", "CheckedSpinBox", "DockBehaviour", "install_app_filter", "install_dock_behaviour",
    "is_undo_key",
    "takes_wheel_only_when_focused", "text_being_edited",
]
