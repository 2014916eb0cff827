"""Help ▸ User Guide and Keyboard Reference: the Markdown pages shipped with the package.

The pages come from :func:`qtanimator.paths.docs_dir` (``qtanimator/docs`` in an installed
wheel, ``docs/`` in a checkout), shown in a QTextBrowser that renders Markdown with its
pictures and follows links between the pages; web links open in the browser.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QUrl
from PySide6.QtGui import QDesktopServices, QTextDocument
from PySide6.QtWidgets import QDialog, QDialogButtonBox, QTextBrowser, QVBoxLayout, QWidget

from qtanimator.paths import docs_dir

#: Help pages by name: (file in the docs folder, window title).
PAGES = {
    "user-guide": ("user-guide.md", "qtanimator User Guide"),
    "keyboard": ("keyboard.md", "qtanimator Keyboard Reference"),
}


class HelpViewer(QDialog):
    """A window showing one help page; links to the other pages open in it."""

    def __init__(self, page: Path, title: str, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("helpViewer")
        self.setWindowTitle(title)
        self.resize(820, 720)
        layout = QVBoxLayout(self)
        self.browser = QTextBrowser(self)
        self.browser.setObjectName("helpBrowser")
        self.browser.setOpenLinks(False)  # markdown pages, anchors and the web: see _follow
        self.browser.anchorClicked.connect(self._follow)
        self.browser.setSearchPaths([str(page.parent)])
        layout.addWidget(self.browser)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close)
        buttons.rejected.connect(self.close)
        layout.addWidget(buttons)
        self.show_page(page)

    def show_page(self, page: Path, fragment: str = "") -> None:
        url = QUrl.fromLocalFile(str(page))
        if fragment:
            url.setFragment(fragment)
        self.browser.setSource(url, QTextDocument.ResourceType.MarkdownResource)

    def _follow(self, url: QUrl) -> None:
        if url.scheme() in ("http", "https", "mailto"):
            QDesktopServices.openUrl(url)
            return
        if not url.path() or url.path() == self.browser.source().path():
            self.browser.scrollToAnchor(url.fragment())
            return
        target = Path(self.browser.source().toLocalFile()).parent / url.path()
        if target.suffix.lower() == ".md" and target.is_file():
            self.show_page(target, url.fragment())
        elif target.exists():
            QDesktopServices.openUrl(QUrl.fromLocalFile(str(target)))


def page_path(name: str) -> Path:
    return docs_dir() / PAGES[name][0]


def open_help(parent: QWidget, name: str) -> HelpViewer | None:
    """Show (or raise) the viewer of page ``name``; None when the page is not installed."""
    path = page_path(name)
    if not path.is_file():
        return None
    viewer = parent.findChild(HelpViewer, f"helpViewer-{name}")
    if viewer is None:
        viewer = HelpViewer(path, PAGES[name][1], parent)
        viewer.setObjectName(f"helpViewer-{name}")
    viewer.show()
    viewer.raise_()
    viewer.activateWindow()
    return viewer
