"""Validated access to a glTF's JSON and the binary data of its buffer views and
accessors (sparse ones too), within a decoded-data budget; every error names where the
problem is."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.formats.errors import FormatError
from qtanimator.formats.gltf.constants import (
    COMPONENTS,
    FLOAT,
    MAX_ZERO_ELEMENTS,
    TYPES,
    UNSIGNED_BYTE,
    UNSIGNED_INT,
    UNSIGNED_SHORT,
)
from qtanimator.formats.limits import decoded_budget, exceeded

FloatArray = npt.NDArray[np.float64]


class Reader:
    """Validating access to the JSON with errors that name where the problem is."""

    def __init__(self, doc: dict[str, Any], buffers: list[bytes], path: str | None,
                 input_bytes: int = 0) -> None:
        self.doc = doc
        self.buffers = buffers
        self.path = path
        self._accessors: dict[int, Any] = {}
        #: Bytes of decoded accessor data allowed (proportional to the input, capped).
        self.budget = decoded_budget(input_bytes + sum(len(b) for b in buffers))
        self.decoded = 0
        self.vertices = 0

    def spend(self, nbytes: int, where: str) -> None:
        """Count ``nbytes`` of decoded data against the budget before allocating them."""
        self.decoded += nbytes
        if self.decoded > self.budget:
            raise exceeded(f"{where}: the decoded data ({self.decoded} bytes so far)",
                           f"{self.budget} bytes for a file of this size", self.path)

    def error(self, message: str) -> FormatError:
        return FormatError(message, self.path)

    # ---------------------------------------------------------------- JSON access
    def array(self, obj: Mapping[str, Any], key: str, where: str) -> list[Any]:
        value = obj.get(key, [])
        if not isinstance(value, list):
            raise self.error(f"{where}.{key} must be an array.")
        return value

    def obj(self, value: Any, where: str) -> dict[str, Any]:
        if not isinstance(value, dict):
            raise self.error(f"{where} must be an object.")
        return value

    def integer(self, obj: Mapping[str, Any], key: str, where: str, *, required: bool = False,
                default: int | None = None, minimum: int = 0, count: int | None = None) -> int | None:
        value = obj.get(key)
        if value is None:
            if required:
                raise self.error(f"{where} has no '{key}'.")
            return default
        return self.whole(value, f"{where}.{key}", minimum, count)

    def whole(self, value: Any, label: str, minimum: int = 0, count: int | None = None) -> int:
        if (isinstance(value, bool) or not isinstance(value, int | float)
                or (isinstance(value, float) and not (math.isfinite(value) and value == int(value)))):
            raise self.error(f"{label} must be a whole number, found {short(value)}.")
        v = int(value)
        if v < minimum:
            raise self.error(f"{label} must be at least {minimum}, found {v}.")
        if count is not None and v >= count:
            raise self.error(f"{label} is {v}, but there are only {count}.")
        return v

    def item(self, value: Any, where: str, count: int) -> int:
        """An array element that must be an index below ``count``."""
        return self.whole(value, where, 0, count)

    def index(self, obj: Mapping[str, Any], key: str, where: str, collection: str,
              required: bool = False) -> int | None:
        count = len(self.doc.get(collection, []) or [])
        return self.integer(obj, key, where, required=required, count=count)

    def numbers(self, obj: Mapping[str, Any], key: str, where: str, length: int) -> FloatArray | None:
        value = obj.get(key)
        if value is None:
            return None
        if (not isinstance(value, list) or len(value) != length
                or not all(isinstance(x, int | float) and not isinstance(x, bool) for x in value)):
            raise self.error(f"{where}.{key} must be an array of {length} numbers.")
        arr = np.array(value, dtype=np.float64)
        if not np.isfinite(arr).all():
            raise self.error(f"{where}.{key} holds a number that is too large.")
        return arr

    def string(self, obj: Mapping[str, Any], key: str, where: str, default: str = "") -> str:
        value = obj.get(key, default)
        if not isinstance(value, str):
            raise self.error(f"{where}.{key} must be a string.")
        return value

    def collection(self, key: str) -> list[dict[str, Any]]:
        items = self.array(self.doc, key, "the glTF")
        return [self.obj(item, f"{key}[{i}]") for i, item in enumerate(items)]

    # ---------------------------------------------------------------- binary data
    def buffer_view(self, index: int, where: str) -> tuple[bytes, int, int, int | None]:
        """``(buffer bytes, start, length, byteStride)`` of buffer view ``index``."""
        views = self.collection("bufferViews")
        if not 0 <= index < len(views):
            raise self.error(f"{where} refers to buffer view {index}, but there are {len(views)}.")
        view = views[index]
        vw = f"bufferViews[{index}]"
        b = self.integer(view, "buffer", vw, required=True, count=len(self.buffers))
        offset = self.integer(view, "byteOffset", vw, default=0) or 0
        length = self.integer(view, "byteLength", vw, required=True, minimum=1) or 0
        stride = self.integer(view, "byteStride", vw, minimum=4)
        data = self.buffers[b or 0]
        if offset + length > len(data):
            raise self.error(f"{vw} covers bytes {offset}..{offset + length} of buffer {b}, "
                             f"which has only {len(data)}.")
        return data, offset, length, stride

    def accessor(self, index: int, where: str) -> npt.NDArray[Any]:
        """Accessor ``index`` as a (count, components) array: float64 for FLOAT and
        normalized types, int64 otherwise. Matrices come out column-major, flattened."""
        if index in self._accessors:
            result: npt.NDArray[Any] = self._accessors[index]
            return result
        accessors = self.collection("accessors")
        if not 0 <= index < len(accessors):
            raise self.error(f"{where} refers to accessor {index}, but there are {len(accessors)}.")
        acc = accessors[index]
        aw = f"accessors[{index}]"
        ctype = self.integer(acc, "componentType", aw, required=True)
        if ctype not in COMPONENTS:
            raise self.error(f"{aw}.componentType {ctype} is not a glTF component type.")
        kind = acc.get("type")
        if kind not in TYPES:
            raise self.error(f"{aw}.type must be SCALAR, VEC2, VEC3, VEC4, MAT2, MAT3 or MAT4, "
                             f"found {short(kind)}.")
        count = self.integer(acc, "count", aw, required=True, minimum=1) or 0
        normalized = acc.get("normalized", False)
        if not isinstance(normalized, bool):
            raise self.error(f"{aw}.normalized must be true or false.")
        dtype_code, csize = COMPONENTS[ctype]
        cols, rows = TYPES[kind]
        ncomp = cols * rows
        col_bytes = rows * csize
        col_stride = col_bytes + ((-col_bytes) % 4 if cols > 1 else 0)
        elem = col_stride * cols
        view_index = self.integer(acc, "bufferView", aw)
        # What this accessor will hold, decoded (8-byte numbers), counted before allocation:
        # many accessors sharing one small view must not expand without bound.
        self.spend(count * ncomp * 8 * (2 if acc.get("sparse") is not None else 1), aw)
        if view_index is None:
            if count * ncomp > MAX_ZERO_ELEMENTS:
                raise self.error(f"{aw} has no buffer view and {count} elements; that is too many.")
            raw = np.zeros((count, ncomp), dtype=dtype_code)
        else:
            data, start, length, stride = self.buffer_view(view_index, aw)
            offset = self.integer(acc, "byteOffset", aw, default=0) or 0
            stride = stride or elem
            if stride < elem:
                raise self.error(f"bufferViews[{view_index}].byteStride {stride} is smaller than an "
                                 f"element of {aw} ({elem} bytes).")
            need = offset + stride * (count - 1) + elem
            if need > length:
                raise self.error(f"{aw} needs {need} bytes of buffer view {view_index}, which has {length}.")
            dt = np.dtype(dtype_code)
            strided = np.ndarray((count, cols, rows), dtype=dt, buffer=data, offset=start + offset,
                                 strides=(stride, col_stride, csize))
            raw = strided.reshape(count, ncomp).copy()
        sparse = acc.get("sparse")
        if sparse is not None:
            raw = self.apply_sparse(raw, self.obj(sparse, f"{aw}.sparse"), aw, dtype_code, count, cols, rows)
        if ctype == FLOAT:
            with np.errstate(invalid="ignore"):  # a signalling NaN warns when cast; refused below
                out: npt.NDArray[Any] = raw.astype(np.float64)
            if not np.isfinite(out).all():
                raise self.error(f"{aw} holds values that are not finite numbers.")
        elif normalized:
            if ctype == UNSIGNED_INT:
                raise self.error(f"{aw} cannot be normalized with unsigned int components.")
            info = np.iinfo(np.dtype(dtype_code))
            out = np.maximum(raw.astype(np.float64) / info.max, -1.0)
        else:
            out = raw.astype(np.int64)
        self._accessors[index] = out
        return out

    def apply_sparse(self, raw: npt.NDArray[Any], sparse: dict[str, Any], aw: str, dtype_code: str,
                     count: int, cols: int, rows: int) -> npt.NDArray[Any]:
        sw = f"{aw}.sparse"
        n = self.integer(sparse, "count", sw, required=True, minimum=1) or 0
        if n > count:
            raise self.error(f"{sw}.count {n} is more than the accessor's {count} elements.")
        idx_obj = self.obj(sparse.get("indices"), f"{sw}.indices")
        val_obj = self.obj(sparse.get("values"), f"{sw}.values")
        ictype = self.integer(idx_obj, "componentType", f"{sw}.indices", required=True)
        if ictype not in (UNSIGNED_BYTE, UNSIGNED_SHORT, UNSIGNED_INT):
            raise self.error(f"{sw}.indices.componentType must be an unsigned integer type.")
        icode, isize = COMPONENTS[ictype or UNSIGNED_INT]
        indices = self._sparse_block(idx_obj, f"{sw}.indices", np.dtype(icode), n, 1).reshape(n).astype(np.int64)
        if indices.max() >= count:
            raise self.error(f"{sw}.indices refers to element {int(indices.max())} of {count}.")
        if np.any(np.diff(indices) <= 0):
            raise self.error(f"{sw}.indices must increase strictly.")
        values = self._sparse_block(val_obj, f"{sw}.values", np.dtype(dtype_code), n, cols * rows)
        raw = raw.copy()
        raw[indices] = values.reshape(n, cols * rows)
        return raw

    def _sparse_block(self, obj: dict[str, Any], where: str, dt: np.dtype[Any], n: int, ncomp: int) -> npt.NDArray[Any]:
        view = self.integer(obj, "bufferView", where, required=True) or 0
        data, start, length, _ = self.buffer_view(view, where)
        offset = self.integer(obj, "byteOffset", where, default=0) or 0
        need = offset + n * ncomp * dt.itemsize
        if need > length:
            raise self.error(f"{where} needs {need} bytes of buffer view {view}, which has {length}.")
        return np.frombuffer(data, dtype=dt, count=n * ncomp, offset=start + offset).copy()


def short(value: Any, limit: int = 40) -> str:
    """``repr(value)``, cut to ``limit`` characters for an error message."""
    text = repr(value)
    return text if len(text) <= limit else text[:limit] + "…"
