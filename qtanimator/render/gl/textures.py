"""Image textures for meshes: decoding a document's :class:`~qtanimator.document.character3d.TextureImage`
with Qt (QImage: PNG, JPEG, BMP, …) and uploading it as a GL texture, or a checkerboard when
the image is missing or cannot be decoded.

Images are uploaded top row first, so texture coordinate t = 0 is the image's top edge (as
glTF's v); :mod:`qtanimator.render.scene3d` flips the v of course files (origin bottom left).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from OpenGL import GL
from PySide6.QtCore import QByteArray
from PySide6.QtGui import QImage

#: The checkerboard drawn for a missing image: 8 × 8 cells of magenta and dark grey.
CHECKER_COLORS = ((255, 0, 255, 255), (48, 48, 48, 255))
CHECKER_CELLS = 8


def checkerboard(size: int = 64, cells: int = CHECKER_CELLS) -> np.ndarray:
    """(size, size, 4) uint8 RGBA: ``cells`` × ``cells`` squares of the two CHECKER_COLORS."""
    idx = (np.arange(size) * cells // size)
    odd = (idx[:, None] + idx[None, :]) % 2
    return np.asarray(CHECKER_COLORS, dtype=np.uint8)[odd]


def qimage_rgba(image: QImage) -> np.ndarray | None:
    """A QImage as (H, W, 4) uint8 RGBA, top row first (None for a null image)."""
    if image.isNull():
        return None
    img = image.convertToFormat(QImage.Format.Format_RGBA8888)
    w, h, stride = img.width(), img.height(), img.bytesPerLine()
    buf = np.frombuffer(img.constBits(), dtype=np.uint8, count=stride * h).reshape(h, stride)
    return buf[:, : 4 * w].reshape(h, w, 4).copy()


def decode(texture: Any) -> np.ndarray | None:
    """The pixels of a TextureImage (embedded bytes or a file), or None when there is no
    image or Qt cannot decode it."""
    data = texture.read() if hasattr(texture, "read") else getattr(texture, "data", None)
    if not data:
        return None
    image = QImage()
    if not image.loadFromData(QByteArray(bytes(data))):
        return None
    return qimage_rgba(image)


def texture_pixels(texture: Any) -> tuple[np.ndarray, bool]:
    """(RGBA pixels, decoded): the image, or the checkerboard with ``decoded`` False."""
    rgba = decode(texture)
    if rgba is None or rgba.size == 0:
        return checkerboard(), False
    return rgba, True


def upload(rgba: np.ndarray, wrap: str = "repeat", nearest: bool = False) -> int:
    """A GL_TEXTURE_2D with mipmaps from (H, W, 4) uint8 RGBA; returns its name."""
    data = np.ascontiguousarray(rgba, dtype=np.uint8)
    h, w = data.shape[:2]
    tex = int(GL.glGenTextures(1))
    GL.glBindTexture(GL.GL_TEXTURE_2D, tex)
    GL.glPixelStorei(GL.GL_UNPACK_ALIGNMENT, 1)
    GL.glTexImage2D(GL.GL_TEXTURE_2D, 0, GL.GL_RGBA8, w, h, 0, GL.GL_RGBA, GL.GL_UNSIGNED_BYTE, data)
    GL.glPixelStorei(GL.GL_UNPACK_ALIGNMENT, 4)
    GL.glGenerateMipmap(GL.GL_TEXTURE_2D)
    mode = GL.GL_CLAMP_TO_EDGE if wrap == "clamp" else GL.GL_REPEAT
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_WRAP_S, mode)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_WRAP_T, mode)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_MIN_FILTER,
                       GL.GL_NEAREST_MIPMAP_NEAREST if nearest else GL.GL_LINEAR_MIPMAP_LINEAR)
    GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_MAG_FILTER, GL.GL_NEAREST if nearest else GL.GL_LINEAR)
    GL.glBindTexture(GL.GL_TEXTURE_2D, 0)
    return tex


class TextureCache:
    """GL textures per TextureImage (by identity), uploaded on first use; a texture no frame
    used since the last :meth:`sweep` is deleted then."""

    def __init__(self) -> None:
        self._textures: dict[int, tuple[Any, int, bool]] = {}
        self._used: set[int] = set()

    def get(self, texture: Any) -> int:
        key = id(texture)
        self._used.add(key)
        cached = self._textures.get(key)
        if cached is not None and cached[0] is texture:
            return cached[1]
        if cached is not None:
            GL.glDeleteTextures(1, [cached[1]])
        rgba, decoded = texture_pixels(texture)
        name = upload(rgba, getattr(texture, "wrap", "repeat"), nearest=not decoded)
        self._textures[key] = (texture, name, decoded)
        return name

    def decoded(self, texture: Any) -> bool | None:
        """Whether the texture's image decoded (None: not uploaded yet)."""
        cached = self._textures.get(id(texture))
        return None if cached is None or cached[0] is not texture else cached[2]

    def sweep(self) -> None:
        for key in [k for k in self._textures if k not in self._used]:
            GL.glDeleteTextures(1, [self._textures.pop(key)[1]])
        self._used = set()

    def release(self) -> None:
        for _t, name, _d in self._textures.values():
            GL.glDeleteTextures(1, [name])
        self._textures.clear()
        self._used = set()
