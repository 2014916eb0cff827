"""The main window: menus, dock areas and the central editors over one document.

Each editor lives in its own module with an ``install(window)`` function that adds its
widgets and actions; :data:`EDITOR_MODULES` lists them in the order they are installed
(tests may install a subset by short name).
Object names of docks, views and actions are part of the interface (ARCHITECTURE §7).
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable, Collection
from pathlib import Path

import shiboken6
from PySide6.QtCore import QByteArray, QSettings, Qt
from PySide6.QtGui import QAction, QCloseEvent, QDragEnterEvent, QDropEvent, QKeySequence
from PySide6.QtWidgets import (
    QDockWidget,
    QFileDialog,
    QMainWindow,
    QMessageBox,
    QTabWidget,
    QUndoView,
    QWidget,
)

from qtanimator import __version__
from qtanimator.document.document import Document
from qtanimator.document.io import open_document, save_document
from qtanimator.formats.errors import FormatError
from qtanimator.ui.context import EditorContext

PROJECT_SUFFIX = ".qtanim"
PROJECT_FILTER = "qtanimator projects (*.qtanim *.json)"
MAX_RECENT = 10

#: Editor modules installed into every window, in order. Each has ``install(window)``.
EDITOR_MODULES: list[str] = [
    "qtanimator.ui.rig_editor",
    "qtanimator.ui.viewport",
    "qtanimator.ui.import3d",
    "qtanimator.ui.timeline",
    "qtanimator.ui.joint_tree",
    "qtanimator.ui.properties",
    "qtanimator.ui.curve_editor",
    "qtanimator.ui.cloth_panel",
    "qtanimator.ui.light_panel",
    "qtanimator.ui.export_dialog",
    "qtanimator.ui.recovery",
]

#: Openers for files that are not projects, by lower-case suffix; editors register them.
Opener = Callable[["MainWindow", Path], None]


def settings() -> QSettings:
    """The program's settings; tests point QTANIMATOR_SETTINGS_DIR at a temporary folder."""
    folder = os.environ.get("QTANIMATOR_SETTINGS_DIR")
    if folder:
        return QSettings(str(Path(folder) / "qtanimator.ini"), QSettings.Format.IniFormat)
    return QSettings("qtanimator", "qtanimator")


class MainWindow(QMainWindow):
    def __init__(self, doc: Document | None = None,
                 install_editors: bool | Collection[str] = True) -> None:
        """``install_editors``: True for every editor, False for the bare shell, or the
        short names of the editor modules to install (``{"timeline", "rig_editor"}``)."""
        super().__init__()
        self.setObjectName("mainWindow")
        self.ctx = EditorContext(doc, self)
        self.openers: dict[str, Opener] = {}
        #: Called before the document is written (Save, Save As, autosave): editors put view
        #: state such as the 3D camera into the document here, without an undo step.
        self.save_hooks: list[Callable[[], None]] = []
        self.setAcceptDrops(True)
        self.setDockNestingEnabled(True)
        self.resize(1400, 900)

        self.central_tabs = QTabWidget(self)
        self.central_tabs.setObjectName("centralTabs")
        self.central_tabs.setDocumentMode(True)
        self.setCentralWidget(self.central_tabs)

        self._build_menus()
        self._build_undo_history()
        for name in EDITOR_MODULES:
            short = name.rsplit(".", 1)[1]
            if install_editors is True or (install_editors and short in install_editors):
                importlib.import_module(name).install(self)
        # The undo stack is cleared while the window is destroyed: ignore that signal then.
        self.ctx.undo_stack.cleanChanged.connect(
            lambda _clean: shiboken6.isValid(self) and self._update_title())
        self.ctx.documentReset.connect(self._update_title)
        self._default_layout()
        self._restore_layout()
        self._update_title()

    # ------------------------------------------------------------------- shell
    @property
    def doc(self) -> Document:
        return self.ctx.doc

    def add_dock(self, object_name: str, title: str, widget: QWidget,
                 area: Qt.DockWidgetArea = Qt.DockWidgetArea.RightDockWidgetArea) -> QDockWidget:
        """Add a dock with a stable object name and a toggle in the View menu."""
        dock = QDockWidget(title, self)
        dock.setObjectName(object_name)
        dock.setWidget(widget)
        self.addDockWidget(area, dock)
        self.view_menu.addAction(dock.toggleViewAction())
        return dock

    def add_central(self, widget: QWidget, title: str) -> None:
        self.central_tabs.addTab(widget, title)

    def _action(self, name: str, text: str, slot: Callable[[], object],
                shortcut: QKeySequence | QKeySequence.StandardKey | str | None = None) -> QAction:
        action = QAction(text, self)
        action.setObjectName(name)
        if shortcut is not None:
            action.setShortcut(QKeySequence(shortcut))
        action.triggered.connect(lambda _checked=False: slot())
        return action

    def _build_menus(self) -> None:
        bar = self.menuBar()
        self.file_menu = bar.addMenu("&File")
        self.edit_menu = bar.addMenu("&Edit")
        self.view_menu = bar.addMenu("&View")
        self.help_menu = bar.addMenu("&Help")

        self.action_new = self._action("actionNew", "&New", self.new_document, QKeySequence.StandardKey.New)
        self.action_open = self._action("actionOpen", "&Open…", self.open_dialog, QKeySequence.StandardKey.Open)
        self.action_save = self._action("actionSave", "&Save", self.save, QKeySequence.StandardKey.Save)
        self.action_save_as = self._action("actionSaveAs", "Save &As…", self.save_as,
                                           QKeySequence.StandardKey.SaveAs)
        self.action_quit = self._action("actionQuit", "&Quit", self.close, QKeySequence.StandardKey.Quit)
        self.recent_menu = self.file_menu.addMenu("Open &Recent")
        self.recent_menu.setObjectName("menuRecent")
        self.file_menu.insertAction(self.recent_menu.menuAction(), self.action_new)
        self.file_menu.insertAction(self.recent_menu.menuAction(), self.action_open)
        self.file_menu.addSeparator()
        self.file_menu.addAction(self.action_save)
        self.file_menu.addAction(self.action_save_as)
        self.file_menu.addSeparator()
        self.export_separator = self.file_menu.addSeparator()
        self.file_menu.addAction(self.action_quit)
        self._refresh_recent_menu()

        stack = self.ctx.undo_stack
        self.action_undo = stack.createUndoAction(self, "&Undo")
        self.action_undo.setObjectName("actionUndo")
        self.action_undo.setShortcut(QKeySequence.StandardKey.Undo)
        self.action_redo = stack.createRedoAction(self, "&Redo")
        self.action_redo.setObjectName("actionRedo")
        self.action_redo.setShortcuts([QKeySequence.StandardKey.Redo, QKeySequence("Ctrl+Y")])
        self.edit_menu.addAction(self.action_undo)
        self.edit_menu.addAction(self.action_redo)
        self.edit_menu.addSeparator()

        about = self._action("actionAbout", "&About qtanimator", self._about)
        self.help_menu.addAction(about)

    def _build_undo_history(self) -> None:
        view = QUndoView(self.ctx.undo_stack)
        view.setObjectName("undoHistoryView")
        view.setEmptyLabel("<original>")
        self.undo_history_dock = self.add_dock("undoHistoryDock", "Undo History", view,
                                               Qt.DockWidgetArea.RightDockWidgetArea)
        self.undo_history_dock.hide()

    def _about(self) -> None:
        QMessageBox.about(self, "About qtanimator",
                          f"qtanimator {__version__}\nCharacter animation: 2D rigs, curves, 3D and cloth.")

    # ---------------------------------------------------------------- errors
    def show_error(self, title: str, text: str) -> None:
        """Tell the user something went wrong (a modal dialog)."""
        QMessageBox.critical(self, title, text)

    # ----------------------------------------------------------------- files
    def is_modified(self) -> bool:
        return not self.ctx.undo_stack.isClean()

    def maybe_save(self) -> bool:
        """Ask about unsaved changes. Returns False if the user cancels."""
        if not self.is_modified():
            return True
        answer = QMessageBox.question(
            self, "Unsaved changes", "The project has unsaved changes. Save them first?",
            QMessageBox.StandardButton.Save | QMessageBox.StandardButton.Discard
            | QMessageBox.StandardButton.Cancel, QMessageBox.StandardButton.Save)
        if answer == QMessageBox.StandardButton.Save:
            return self.save()
        return answer == QMessageBox.StandardButton.Discard

    def new_document(self) -> None:
        if self.maybe_save():
            self.ctx.replace_document(Document())

    def replaces_document(self, path: str | os.PathLike[str]) -> bool:
        """True for a project (it replaces the document); other files are added to it."""
        p = Path(path)
        return not p.is_dir() and p.suffix.lower() not in self.openers

    def open_with_prompt(self, path: str | os.PathLike[str]) -> bool:
        """Open ``path``, first offering to save unsaved changes if it replaces the document."""
        if self.replaces_document(path) and not self.maybe_save():
            return False
        return self.open_path(path)

    def open_dialog(self) -> None:
        suffixes = " ".join(f"*{s}" for s in sorted(self.openers))
        filters = f"All supported ({'*.qtanim *.json ' + suffixes});;{PROJECT_FILTER};;All files (*)"
        path, _ = QFileDialog.getOpenFileName(self, "Open", self._last_dir(), filters)
        if path:
            self.open_with_prompt(path)

    def open_path(self, path: str | os.PathLike[str]) -> bool:
        """Open a project, or hand another file to the editor that reads it.

        A file that cannot be read shows the reader's sentence and changes nothing.
        """
        p = Path(path)
        opener = None if p.is_dir() else self.openers.get(p.suffix.lower())
        if p.is_dir():
            opener = self.openers.get("/")
        try:
            if opener is not None:
                opener(self, p)
            elif p.suffix.lower() in (PROJECT_SUFFIX, ".json"):
                self.ctx.replace_document(open_document(p))
            else:
                raise FormatError("qtanimator does not know this kind of file.", p)
        except FormatError as exc:
            self._forget_if_gone(p)
            self.show_error("Cannot open file", str(exc))
            return False
        except OSError as exc:
            self._forget_if_gone(p)
            self.show_error("Cannot open file", f"{p.name}: {exc.strerror or exc}")
            return False
        self._remember_recent(p)
        self._update_title()
        return True

    def save(self) -> bool:
        if self.doc.path is None:
            return self.save_as()
        return self.save_to(self.doc.path)

    def save_as(self) -> bool:
        start = self.doc.path or str(Path(self._last_dir()) / f"untitled{PROJECT_SUFFIX}")
        path, _ = QFileDialog.getSaveFileName(self, "Save Project", start, PROJECT_FILTER)
        if not path:
            return False
        if not Path(path).suffix:
            path += PROJECT_SUFFIX
        return self.save_to(path)

    def prepare_save(self) -> None:
        """Let the editors store their view state in the document (see ``save_hooks``)."""
        for hook in self.save_hooks:
            hook()

    def save_to(self, path: str | os.PathLike[str]) -> bool:
        try:
            self.prepare_save()
            save_document(self.doc, path)
        except (OSError, ValueError) as exc:
            self.show_error("Cannot save", f"{Path(path).name}: {exc}")
            return False
        self.ctx.undo_stack.setClean()
        self._remember_recent(Path(path))
        self._update_title()
        return True

    def _last_dir(self) -> str:
        return str(settings().value("lastDir", str(Path.home())))

    def recent_files(self) -> list[str]:
        value = settings().value("recentFiles", [])
        if isinstance(value, str):
            value = [value]
        return [str(v) for v in (value or [])]

    def _remember_recent(self, path: Path) -> None:
        s = settings()
        full = str(path.resolve())
        recent = [full] + [r for r in self.recent_files() if r != full]
        s.setValue("recentFiles", recent[:MAX_RECENT])
        s.setValue("lastDir", str(path.resolve().parent))
        self._refresh_recent_menu()

    def _forget_if_gone(self, path: Path) -> None:
        """A recent file that no longer exists leaves the Recent menu."""
        if path.exists():
            return
        full = str(path.resolve())
        recent = self.recent_files()
        if full in recent:
            settings().setValue("recentFiles", [r for r in recent if r != full])
            self._refresh_recent_menu()

    def _refresh_recent_menu(self) -> None:
        self.recent_menu.clear()
        for path in self.recent_files():
            action = self.recent_menu.addAction(Path(path).name)
            action.setToolTip(path)
            action.triggered.connect(lambda _c=False, p=path: self.open_with_prompt(p))
        self.recent_menu.setEnabled(bool(self.recent_files()))

    def _update_title(self) -> None:
        name = Path(self.doc.path).name if self.doc.path else "untitled"
        self.setWindowTitle(f"{name}[*] — qtanimator")
        self.setWindowModified(self.is_modified())

    # ------------------------------------------------------- drag and drop
    def dragEnterEvent(self, event: QDragEnterEvent) -> None:
        if event.mimeData().hasUrls():
            event.acceptProposedAction()

    def dropEvent(self, event: QDropEvent) -> None:
        urls = [u.toLocalFile() for u in event.mimeData().urls() if u.isLocalFile()]
        if urls:
            self.open_with_prompt(urls[0])
            event.acceptProposedAction()

    # --------------------------------------------------------------- layout
    def _default_layout(self) -> None:
        """First-run arrangement: curve editor above the timeline along the bottom, the
        joint tree on the left, properties / cloth / lights as tabs on the right."""
        def dock(name: str) -> QDockWidget | None:
            return self.findChild(QDockWidget, name)

        curve, timeline = dock("curveEditorDock"), dock("timelineDock")
        if curve is not None and timeline is not None:
            self.addDockWidget(Qt.DockWidgetArea.BottomDockWidgetArea, curve)
            self.addDockWidget(Qt.DockWidgetArea.BottomDockWidgetArea, timeline)
            self.splitDockWidget(curve, timeline, Qt.Orientation.Vertical)
            self.resizeDocks([curve, timeline], [300, 130], Qt.Orientation.Vertical)
        right = [d for d in (dock("propertiesDock"), dock("clothDock"), dock("lightDock")) if d is not None]
        for other in right[1:]:
            self.tabifyDockWidget(right[0], other)
        if right:
            right[0].raise_()
            self.resizeDocks([right[0]], [380], Qt.Orientation.Horizontal)
        tree = dock("jointTreeDock")
        if tree is not None:
            self.resizeDocks([tree], [260], Qt.Orientation.Horizontal)

    def _restore_layout(self) -> None:
        s = settings()
        geometry = s.value("window/geometry")
        state = s.value("window/state")
        if isinstance(geometry, QByteArray):
            self.restoreGeometry(geometry)
        if isinstance(state, QByteArray):
            self.restoreState(state)

    def closeEvent(self, event: QCloseEvent) -> None:
        if not self.maybe_save():
            event.ignore()
            return
        s = settings()
        s.setValue("window/geometry", self.saveGeometry())
        s.setValue("window/state", self.saveState())
        event.accept()
