"""What the parts of the 3D view share.

:class:`~qtanimator.ui.view3d.Viewport3D` is put together from one mixin per idea
(camera navigation, picking, drags, live cloth, keys). Each mixin derives from
:class:`ViewPart`, which names for the type checker the state and the methods the view
provides (set in ``Viewport3D.__init__``); at run time it is a plain ``object`` base, so the
mixins add methods only and ``QWidget`` stays the view's one Qt base.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar

from PySide6.QtCore import Signal
from PySide6.QtWidgets import QWidget

from qtanimator.document.cloth_worker import ClothWorker
from qtanimator.document.live_cloth import LiveCloths
from qtanimator.render.gl.camera import OrbitCamera
from qtanimator.render.gl.renderer import SceneItem, ViewOptions
from qtanimator.ui.context import EditorContext

if TYPE_CHECKING:
    _Widget = QWidget
else:
    _Widget = object


class ViewPart(_Widget):
    """The base of the 3D view's mixins: what they may use of the view."""

    ctx: EditorContext
    camera: OrbitCamera
    options: ViewOptions
    #: The interactive cloths (stepped on their own thread while enabled).
    live: LiveCloths
    #: Fills the document's cloth caches on a background thread.
    cloth_worker: ClothWorker
    ik_chain_length: int
    #: What the last picture showed (picked and framed against).
    _items: list[SceneItem]
    #: The mouse drag in progress: its mode, last position, and the gesture of an edit.
    _drag: dict[str, Any] | None
    _framed_once: bool
    _grid_pending: bool

    cameraChanged: ClassVar[Signal]
    liveClothChanged: ClassVar[Signal]
    clothProgressChanged: ClassVar[Signal]
    displayChanged: ClassVar[Signal]

    if TYPE_CHECKING:
        def build_items(self) -> list[SceneItem]: ...

        def set_display(self, **changes: Any) -> None: ...


__all__ = ["ViewPart"]
