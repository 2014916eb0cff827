"""Parts of the curve editor (:mod:`qtanimator.ui.curve_editor`).

``paths`` (channels as Bézier paths, reduced per pixel column when dense, extrapolation),
``items`` (per-channel drawings and the cached / live / hover layers), ``normalisation``
(display-only −1…1 scaling), ``view`` (the plot and its gestures), ``tree`` (channel
tree), ``fields`` (numeric key fields).
"""
