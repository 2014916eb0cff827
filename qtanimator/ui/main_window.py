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
from PySide6.QtCore import QByteArray, QRect, QSize, Qt
from PySide6.QtGui import (
    QAction,
    QCloseEvent,
    QDragEnterEvent,
    QDropEvent,
    QGuiApplication,
    QIcon,
    QKeySequence,
    QShowEvent,
)
from PySide6.QtWidgets import (
    QApplication,
    QCheckBox,
    QDockWidget,
    QFileDialog,
    QMainWindow,
    QMessageBox,
    QTabWidget,
    QUndoView,
    QWidget,
)

from qtanimator import __version__
from qtanimator.core.cloth_kernels import warm_up
from qtanimator.document.asset_files import ASSETS_FOLDER, file_refs, is_inside
from qtanimator.document.document import Document
from qtanimator.document.io import open_document_relinked, save_document
from qtanimator.formats.errors import FormatError
from qtanimator.paths import app_icon_path, is_sample
from qtanimator.ui import errors, help_viewer
from qtanimator.ui.app_settings import last_dir, save_dir, settings
from qtanimator.ui.asset_collect import collect_into, locate_missing_file, tell_relinked
from qtanimator.ui.context import EditorContext
from qtanimator.ui.recent_files import RecentFiles
from qtanimator.ui.widgets import install_dock_behaviour

PROJECT_SUFFIX = ".qtanim"
PROJECT_FILTER = "qtanimator projects (*.qtanim *.json)"

#: Editor modules installed into every window, in order. Each has ``install(window)``.
EDITOR_MODULES: list[str] = [
    "qtanimator.ui.rig_editor",
    "qtanimator.ui.viewport",
    "qtanimator.ui.import3d",
    "qtanimator.ui.spine",
    "qtanimator.ui.timeline",
    "qtanimator.ui.joint_tree",
    "qtanimator.ui.properties",
    "qtanimator.ui.curve_editor",
    "qtanimator.ui.dope_sheet",
    "qtanimator.ui.cloth_panel",
    "qtanimator.ui.light_panel",
    "qtanimator.ui.export_dialog",
    "qtanimator.ui.recovery",
]

#: The first run's window: this share of the screen's available area (each way), at most
#: :data:`FIRST_RUN_MAX` logical pixels, centred. A layout restored from the settings is
#: clamped to the available area instead (the screen may have changed since).
FIRST_RUN_SHARE = 0.9
FIRST_RUN_MAX = QSize(1600, 1000)
#: On a smaller screen (available area, logical pixels) the first run opens maximised.
SMALL_SCREEN = QSize(1600, 900)
#: On a screen narrower than this (logical pixels: 1920 at scale 2 is 960) the first-run
#: layout has one column of docks: the outliner is a tab beside Properties, Cloth and Lights.
NARROW_SCREEN_WIDTH = 1200
#: First-run dock sizes: the curve editor's share of the window height (at least
#: :data:`CURVE_EDITOR_MIN_HEIGHT`), the timeline's height, the side columns' widths.
CURVE_EDITOR_SHARE = 0.36
CURVE_EDITOR_MIN_HEIGHT = 200
TIMELINE_HEIGHT = 110
OUTLINER_WIDTH = (260, 0.2)   # pixels, at most this share of the window width
SIDE_DOCK_WIDTH = (380, 0.28)

#: The view-state entry (``Document.view_state``) holding the current frame: saved with the
#: project, restored on open, never an edit. (The play range is the project's
#: ``frame_start`` / ``frame_end`` parameters, saved with every project.)
FRAME_VIEW_STATE = "timeline.frame"


def redo_shortcuts() -> list[QKeySequence]:
    """Redo: the platform's keys (Ctrl+Shift+Z) and Ctrl+Y, each once."""
    keys = QKeySequence.keyBindings(QKeySequence.StandardKey.Redo)
    extra = QKeySequence("Ctrl+Y")
    return keys + ([extra] if extra not in keys else [])


#: Openers for files that are not projects, by lower-case suffix; editors register them.
Opener = Callable[["MainWindow", Path], None]


class MainWindow(QMainWindow):
    def __init__(self, doc: Document | None = None,
                 install_editors: bool | Collection[str] = True) -> None:
        """``install_editors``: True for every editor, False for the bare shell, or the
        short names of the editor modules to install (``{"timeline", "rig_editor"}``)."""
        super().__init__()
        # Numba and the cloth kernels load while the window is built, not at the first cloth
        # frame (which would hold the interpreter while the user already plays or drags).
        warm_up()
        self.setObjectName("mainWindow")
        self.setWindowIcon(QIcon(str(app_icon_path())))
        self.ctx = EditorContext(doc, self)
        #: Asset files found at new places when the project was opened: the document differs
        #: from its file although the undo stack is clean (cleared by a save or another open).
        self._relinked_unsaved = False
        #: The bundled sample this untitled document is a copy of (None otherwise): samples
        #: open as untitled copies, so that Save asks where and never writes into them.
        self.sample: Path | None = None
        self.openers: dict[str, Opener] = {}
        #: Called before the document is written (Save, Save As, autosave): editors put view
        #: state such as the 3D camera into the document here, without an undo step.
        self.save_hooks: list[Callable[[], None]] = [self._store_frame]
        # Fields ignore the wheel unless focused; Ctrl+Z undoes the document from any field.
        install_dock_behaviour()
        self.setAcceptDrops(True)
        self.setDockNestingEnabled(True)
        #: True until the first show of a window whose layout came from no settings: the
        #: dock sizes of the first-run layout are set then, when the window has its size.
        self._first_run_docks = False

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
        self.ctx.undo_stack.cleanChanged.connect(self._on_clean_changed)
        self.ctx.documentReset.connect(self._update_title)
        self._default_layout(narrow=self.available_geometry().width() < NARROW_SCREEN_WIDTH)
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
        self.action_collect = self._action("actionCollectAssets", "&Collect Assets…", self.collect_assets)
        self.action_collect.setStatusTip("Copy every file the project uses into its folder, so that the folder "
                                         "can be moved or shared")
        self.action_quit = self._action("actionQuit", "&Quit", self.close, QKeySequence.StandardKey.Quit)
        self.recent_menu = self.file_menu.addMenu("Open &Recent")
        self.recent_menu.setObjectName("menuRecent")
        self.file_menu.insertAction(self.recent_menu.menuAction(), self.action_new)
        self.file_menu.insertAction(self.recent_menu.menuAction(), self.action_open)
        self.file_menu.addSeparator()
        self.file_menu.addAction(self.action_save)
        self.file_menu.addAction(self.action_save_as)
        self.file_menu.addAction(self.action_collect)
        self.file_menu.addSeparator()
        self.export_separator = self.file_menu.addSeparator()
        self.file_menu.addAction(self.action_quit)
        self.recent = RecentFiles(self.recent_menu, self.open_with_prompt)

        stack = self.ctx.undo_stack
        self.action_undo = stack.createUndoAction(self, "&Undo")
        self.action_undo.setObjectName("actionUndo")
        self.action_undo.setShortcut(QKeySequence.StandardKey.Undo)
        self.action_redo = stack.createRedoAction(self, "&Redo")
        self.action_redo.setObjectName("actionRedo")
        self.action_redo.setShortcuts(redo_shortcuts())
        # Undo and redo the document whatever has the focus: a dock field, a floating dock
        # (DockBehaviour lets these keys past a text field that is not being edited).
        for action in (self.action_undo, self.action_redo):
            action.setShortcutContext(Qt.ShortcutContext.ApplicationShortcut)
        self.edit_menu.addAction(self.action_undo)
        self.edit_menu.addAction(self.action_redo)
        self.edit_menu.addSeparator()

        self.help_menu.addAction(self._action("actionUserGuide", "&User Guide", lambda: self.show_help("user-guide"),
                                              QKeySequence.StandardKey.HelpContents))
        self.help_menu.addAction(self._action("actionKeyboardReference", "&Keyboard Reference",
                                              lambda: self.show_help("keyboard")))
        self.help_menu.addSeparator()
        report = self._action("actionReportProblem", "&Report a Problem…", self.report_problem)
        report.setStatusTip("Open the folder of the log file, to attach it to a problem report")
        self.help_menu.addAction(report)
        self.help_menu.addSeparator()
        self.help_menu.addAction(self._action("actionAbout", "&About qtanimator", self._about))
        self.help_menu.addAction(self._action("actionAboutQt", "About &Qt", QApplication.aboutQt))

    def _build_undo_history(self) -> None:
        view = QUndoView(self.ctx.undo_stack)
        view.setObjectName("undoHistoryView")
        view.setEmptyLabel("<original>")
        self.undo_history_dock = self.add_dock("undoHistoryDock", "Undo History", view,
                                               Qt.DockWidgetArea.RightDockWidgetArea)
        self.undo_history_dock.hide()

    def _about(self) -> None:
        QMessageBox.about(self, "About qtanimator",
                          f"qtanimator {__version__}\nCharacter animation: 2D rigs, curves, 3D and cloth.\n"
                          "MIT licence, by the qtanimator contributors.")

    def show_help(self, page: str) -> None:
        """Help ▸ User Guide / Keyboard Reference: the page shipped with the package."""
        if help_viewer.open_help(self, page) is None:
            self.show_error("Help not installed", f"{help_viewer.page_path(page)} is missing from this "
                            "installation.")

    def report_problem(self) -> None:
        """Help ▸ Report a Problem: open the log folder (the log says what went wrong)."""
        from qtanimator import applog

        if not errors.open_log_folder():
            QMessageBox.information(self, "Report a Problem",
                                    f"Attach the log file to your report:\n{applog.log_path()}")

    # ---------------------------------------------------------------- errors
    def show_error(self, title: str, text: str) -> None:
        """Tell the user something went wrong (a modal dialog)."""
        QMessageBox.critical(self, title, text)

    # ----------------------------------------------------------------- files
    def is_modified(self) -> bool:
        return self._relinked_unsaved or not self.ctx.undo_stack.isClean()

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
            self._relinked_unsaved = False
            self.sample = None
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
        path, _ = QFileDialog.getOpenFileName(self, "Open", last_dir(), filters)
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
                self.open_project(p)
            else:
                raise FormatError("qtanimator does not know this kind of file.", p)
        except FormatError as exc:
            self.recent.forget_if_gone(p)
            self.show_error("Cannot open file", str(exc))
            return False
        except OSError as exc:
            self.recent.forget_if_gone(p)
            self.show_error("Cannot open file", f"{p.name}: {exc.strerror or exc}")
            return False
        self.recent.remember(p)
        self._update_title()
        return True

    def open_project(self, p: Path) -> None:
        """Replace the document with the project ``p`` (FormatError / OSError: unchanged).

        A bundled sample (:func:`qtanimator.paths.is_sample`) opens as an untitled copy: its
        assets still come from the sample's folder, and Save asks where (as Save As)."""
        doc, relinks = open_document_relinked(p, lambda ref: locate_missing_file(self, ref))
        self._relinked_unsaved = bool(relinks)
        self.sample = Path(doc.path) if doc.path and is_sample(doc.path) else None
        if self.sample is not None:
            doc.path = None
        self.ctx.replace_document(doc)
        self.restore_view_state()
        if relinks:
            tell_relinked(self, relinks)

    def save(self) -> bool:
        if self.doc.path is None:
            return self.save_as()
        return self.save_to(self.doc.path)

    def save_as(self) -> bool:
        """Ask where (and whether to collect the assets there), then save.

        The dialog starts beside the project, or for an untitled one in the last folder (the
        documents folder when that is a samples folder). A copy of a sample is offered with
        "Collect assets" ticked, so that the saved project does not depend on the
        installation's files (the user's own choice of the box is not changed by that)."""
        if self.doc.path:
            start = self.doc.path
        else:
            name = self.sample.stem if self.sample is not None else "untitled"
            start = str(Path(save_dir()) / f"{name}{PROJECT_SUFFIX}")
        path, collect = self.ask_save_path(start) if self.sample is None else self.ask_save_path(start, collect=True)
        if not path:
            return False
        if not Path(path).suffix:
            path += PROJECT_SUFFIX
        if self.sample is None:
            settings().setValue("collectAssets", collect)
        return self.save_to(path, collect=collect)

    def ask_save_path(self, start: str, collect: bool | None = None) -> tuple[str, bool]:
        """The Save As dialog: a path ("" when cancelled) and the state of its "Copy the
        assets into the project folder" box (``collect``, or when None as at the last Save As)."""
        dialog = QFileDialog(self, "Save Project", start, PROJECT_FILTER)
        dialog.setObjectName("saveAsDialog")
        dialog.setAcceptMode(QFileDialog.AcceptMode.AcceptSave)
        dialog.setDefaultSuffix(PROJECT_SUFFIX.lstrip("."))
        dialog.setOption(QFileDialog.Option.DontUseNativeDialog)  # a native dialog takes no extra widget
        dialog.selectFile(start)
        box = QCheckBox(f"Collect assets: copy every file the project uses into its {ASSETS_FOLDER}/ folder")
        box.setObjectName("collectAssetsCheck")
        box.setToolTip("The project folder then holds everything: it can be moved, zipped or shared.")
        box.setChecked(bool(settings().value("collectAssets", False, type=bool)) if collect is None else collect)
        layout = dialog.layout()
        if layout is not None:
            layout.addWidget(box)
        if not dialog.exec():
            return "", False
        files = dialog.selectedFiles()
        return (files[0] if files else ""), box.isChecked()

    def _store_frame(self) -> None:
        """Save hook: the current frame goes into the view state (no undo step)."""
        self.doc.set_view_state(FRAME_VIEW_STATE, float(self.ctx.frame))

    def restore_view_state(self) -> None:
        """After opening a project: go to the frame it was saved at (when it has one)."""
        stored = self.doc.view_state.get(FRAME_VIEW_STATE)
        if isinstance(stored, (int, float)) and not isinstance(stored, bool) and stored == stored \
                and abs(stored) <= 1e12:  # a frame a view can show (issue 31): not 1e308
            self.ctx.set_frame(float(stored))

    def prepare_save(self) -> None:
        """Let the editors store their view state in the document (see ``save_hooks``)."""
        for hook in self.save_hooks:
            hook()

    def save_to(self, path: str | os.PathLike[str], collect: bool = False) -> bool:
        """Save to ``path``, making its folder when it does not exist; with ``collect``, copy
        the assets into that folder first (one undo step, Collect Assets). A failure shows
        a sentence naming ``path`` and leaves the document as it was.

        Nothing is ever written into the bundled samples (they are part of the installation,
        and a later update would replace them): such a target is refused with a sentence."""
        target = Path(path).absolute()
        if is_sample(target):
            self.show_error("Cannot save", f"{target} is in the samples that come with qtanimator, which are "
                            "never overwritten. Save your copy in another folder.")
            return False
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            self.show_error("Cannot save", f"Cannot make the folder {target.parent} for {target.name}: "
                            f"{exc.strerror or exc}.")
            return False
        if collect and not collect_into(self, self.ctx, target.parent):
            return False
        try:
            self.prepare_save()
            save_document(self.doc, target)
        except OSError as exc:
            # The error names the temporary file the save wrote first: name the target instead.
            self.show_error("Cannot save", f"Cannot save {target}: {exc.strerror or exc}.")
            return False
        except ValueError as exc:
            self.show_error("Cannot save", f"Cannot save {target}: {exc}")
            return False
        self.ctx.undo_stack.setClean()
        self._relinked_unsaved = False
        self.sample = None
        self.recent.remember(target)
        self._update_title()
        return True

    # --------------------------------------------------------------- assets
    def collect_assets(self) -> bool:
        """File ▸ Collect Assets: copy the files the project uses into its folder's
        ``assets/`` and point the project at the copies (one undo step). An untitled
        project is saved first (Save As, with collecting ticked)."""
        if self.doc.path is None:
            name = self.sample.stem if self.sample is not None else "untitled"
            path, _collect = self.ask_save_path(str(Path(save_dir()) / f"{name}{PROJECT_SUFFIX}"))
            if not path:
                return False
            if not Path(path).suffix:
                path += PROJECT_SUFFIX
            return self.save_to(path, collect=True)
        folder = Path(self.doc.path).parent
        outside = [r for r in file_refs(self.doc.assets.values()) if not is_inside(r.path, folder)]
        if not outside:
            QMessageBox.information(self, "Collect Assets", f"Every file the project uses is already in {folder}.")
            return True
        return collect_into(self, self.ctx, folder)

    def recent_files(self) -> list[str]:
        return self.recent.paths()

    def _on_clean_changed(self, _clean: bool) -> None:
        if shiboken6.isValid(self):  # the stack is cleared while the window is destroyed
            self._update_title()

    def _update_title(self) -> None:
        if self.doc.path:
            name = Path(self.doc.path).name
        elif self.sample is not None:
            name = f"{self.sample.stem} (sample) — untitled"
        else:
            name = "untitled"
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
    def available_geometry(self) -> QRect:
        """The available area (without panels and docks of the desktop) of the window's
        screen, in logical pixels."""
        screen = self.screen() or QGuiApplication.primaryScreen()
        return screen.availableGeometry() if screen is not None else QRect(0, 0, 1366, 768)

    def _update_minimum_size(self) -> None:
        """Let the layout set the window's minimum size for the docks as they are now (it
        keeps the one of an earlier arrangement until it is next activated)."""
        layout = self.layout()
        if layout is not None:
            layout.activate()

    def fit_to_screen(self) -> None:
        """The first run's geometry: :data:`FIRST_RUN_SHARE` of the available area, at
        most :data:`FIRST_RUN_MAX`, never below the window's minimum where that fits, centred;
        maximised on a screen smaller than :data:`SMALL_SCREEN`."""
        self._update_minimum_size()
        area = self.available_geometry()
        minimum = self.minimumSizeHint()
        width = min(max(round(area.width() * FIRST_RUN_SHARE), minimum.width()), FIRST_RUN_MAX.width(), area.width())
        height = min(max(round(area.height() * FIRST_RUN_SHARE), minimum.height()), FIRST_RUN_MAX.height(),
                     area.height())
        self.resize(width, height)
        self.move(area.x() + (area.width() - width) // 2, area.y() + (area.height() - height) // 2)
        if area.width() < SMALL_SCREEN.width() or area.height() < SMALL_SCREEN.height():
            # A laptop: every pixel counts, as in Blender and Krita (the size above is what
            # "restore" gives, and what a window system that does not maximise shows).
            self.setWindowState(self.windowState() | Qt.WindowState.WindowMaximized)

    def clamp_to_screen(self) -> None:
        """Make the window (its frame, when the window system has given it one) lie inside
        the available area of its screen: smaller first, then moved."""
        if self.isMaximized() or self.isFullScreen():
            return
        self._update_minimum_size()
        area = self.available_geometry()
        frame, inner = self.frameGeometry(), self.geometry()
        extra_w, extra_h = max(frame.width() - inner.width(), 0), max(frame.height() - inner.height(), 0)
        width = min(inner.width(), area.width() - extra_w)
        height = min(inner.height(), area.height() - extra_h)
        if (width, height) != (inner.width(), inner.height()):
            self.resize(width, height)
        frame = self.frameGeometry()
        x = min(max(frame.x(), area.x()), area.right() + 1 - frame.width())
        y = min(max(frame.y(), area.y()), area.bottom() + 1 - frame.height())
        if (x, y) != (frame.x(), frame.y()):
            self.move(x, y)

    def _default_layout(self, narrow: bool = False) -> None:
        """First-run arrangement: curve editor (the dope sheet as a tab beside it) above the
        timeline along the bottom, the joint tree on the left, properties / cloth / lights as
        tabs on the right. ``narrow`` (a small screen): the joint tree is a tab on the right
        too, so that the window's minimum width fits."""
        def dock(name: str) -> QDockWidget | None:
            return self.findChild(QDockWidget, name)

        curve, timeline = dock("curveEditorDock"), dock("timelineDock")
        if curve is not None and timeline is not None:
            self.addDockWidget(Qt.DockWidgetArea.BottomDockWidgetArea, curve)
            self.addDockWidget(Qt.DockWidgetArea.BottomDockWidgetArea, timeline)
            self.splitDockWidget(curve, timeline, Qt.Orientation.Vertical)
            dope = dock("dopeSheetDock")
            if dope is not None:  # both show keys: a tab beside the curve editor
                self.tabifyDockWidget(curve, dope)
                curve.raise_()
        right = [d for d in (dock("propertiesDock"), dock("clothDock"), dock("lightDock")) if d is not None]
        tree = dock("jointTreeDock")
        if narrow and tree is not None and right:
            self.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, tree)
            right.insert(0, tree)
        for other in right[1:]:
            self.tabifyDockWidget(right[0], other)
        if right:
            right[0].raise_()
        self._first_run_docks = True

    def _size_first_run_docks(self) -> None:
        """The first-run dock sizes for the window's size: the curve editor gets a usable
        height (:data:`CURVE_EDITOR_SHARE`), the side columns a share of the width."""
        def dock(name: str) -> QDockWidget | None:
            found = self.findChild(QDockWidget, name)
            return found if found is not None and not found.isFloating() and found.isVisible() else None

        size = self.size()
        curve, timeline = dock("curveEditorDock"), dock("timelineDock")
        if curve is not None and timeline is not None:
            curve_height = max(round(size.height() * CURVE_EDITOR_SHARE), CURVE_EDITOR_MIN_HEIGHT)
            self.resizeDocks([curve, timeline], [curve_height, TIMELINE_HEIGHT], Qt.Orientation.Vertical)
        for name, (pixels, share) in (("propertiesDock", SIDE_DOCK_WIDTH), ("jointTreeDock", OUTLINER_WIDTH)):
            side = dock(name)
            if side is not None:
                self.resizeDocks([side], [min(pixels, round(size.width() * share))], Qt.Orientation.Horizontal)

    def _restore_layout(self) -> None:
        """The window and dock layout of the last session (clamped to the screen), or the
        first-run size (:meth:`fit_to_screen`)."""
        s = settings()
        geometry = s.value("window/geometry")
        state = s.value("window/state")
        if isinstance(geometry, QByteArray) and self.restoreGeometry(geometry):
            self.clamp_to_screen()
        else:
            self.fit_to_screen()
        if isinstance(state, QByteArray) and self.restoreState(state):
            self._first_run_docks = False

    def showEvent(self, event: QShowEvent) -> None:
        super().showEvent(event)
        if not event.spontaneous():
            self.clamp_to_screen()
        if self._first_run_docks:
            self._first_run_docks = False
            self._size_first_run_docks()

    def closeEvent(self, event: QCloseEvent) -> None:
        if not self.maybe_save():
            event.ignore()
            return
        s = settings()
        s.setValue("window/geometry", self.saveGeometry())
        s.setValue("window/state", self.saveState())
        event.accept()
