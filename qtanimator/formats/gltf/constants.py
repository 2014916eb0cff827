"""glTF 2.0 enumerations and the limits the reader applies (component types, accessor
types, buffer targets, primitive modes, sampler interpolations, animation paths)."""

from __future__ import annotations

BYTE, UNSIGNED_BYTE, SHORT, UNSIGNED_SHORT, UNSIGNED_INT, FLOAT = 5120, 5121, 5122, 5123, 5125, 5126
#: componentType → (numpy dtype code, bytes per component)
COMPONENTS: dict[int, tuple[str, int]] = {
    BYTE: ("i1", 1), UNSIGNED_BYTE: ("u1", 1), SHORT: ("<i2", 2), UNSIGNED_SHORT: ("<u2", 2),
    UNSIGNED_INT: ("<u4", 4), FLOAT: ("<f4", 4),
}
TYPES: dict[str, tuple[int, int]] = {  # type -> (columns, rows)
    "SCALAR": (1, 1), "VEC2": (1, 2), "VEC3": (1, 3), "VEC4": (1, 4),
    "MAT2": (2, 2), "MAT3": (3, 3), "MAT4": (4, 4),
}
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN = 4, 5, 6
INTERPOLATIONS = ("LINEAR", "STEP", "CUBICSPLINE")
PATHS = {"translation": 3, "rotation": 4, "scale": 3, "weights": 0}
#: Largest accessor without a buffer view (all zeros) we build; guards hostile counts.
MAX_ZERO_ELEMENTS = 1 << 26
WEIGHT_SUM_TOLERANCE = 1e-6
