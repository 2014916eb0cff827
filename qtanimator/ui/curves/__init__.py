"""Parts of the curve editor (:mod:`qtanimator.ui.curve_editor`).

``paths`` (channels as Bézier paths, reduced per pixel column when dense, extrapolation),
``items`` (per-channel drawings and the cached / live / hover layers), ``normalisation``
(display-only −1…1 scaling), ``drags`` (what key, handle and box drags do: Qt-free state
machines returning document commands), the plot view in layers — ``plot`` (the widget and
its event routing), ``canvas`` (drawings, display transforms, framing), ``picking`` (hit
tests), ``selection`` (the key selection, kept through edits and shared), ``view`` (mouse
and key gestures: :class:`~.view.CurveView`) — ``tree`` (channel tree), ``fields`` (numeric
key fields).
"""
