"""Parts of the curve editor (:mod:`qtanimator.ui.curve_editor`).

``sampling`` (cached vectorised sampling), ``items`` (drawing layers), ``view`` (the plot
and its gestures), ``tree`` (channel tree), ``fields`` (numeric key fields).
"""
