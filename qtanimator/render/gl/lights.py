"""The two coloured point lights and the ambient term, stored as document parameters.

``light1.position`` / ``light1.color`` / ``light1.intensity`` (and ``light2.*``, and
``lights.ambient``) are ordinary parameters changed with ``SetParameter`` commands, so they
are saved with the project and undoable. Missing parameters take the defaults below
(from the schema, :mod:`qtanimator.document.parameters`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from qtanimator.document.parameters import AMBIENT_PARAMETER, LIGHT_NAMES, LIGHTS, defaults

#: The defaults of the lights' parameters: a view of the schema
#: (:data:`qtanimator.document.parameters.LIGHTS`, which also holds their ranges).
DEFAULTS: dict[str, Any] = defaults(LIGHTS)


@dataclass
class Light:
    position: np.ndarray
    color: np.ndarray
    intensity: float

    @property
    def radiance(self) -> np.ndarray:
        return self.color * self.intensity


def parameter(doc: Any, path: str) -> Any:
    """A light parameter of ``doc`` (or of a plain dict), falling back to its default."""
    params = doc if isinstance(doc, dict) else doc.parameters
    value = params.get(path)
    return DEFAULTS[path] if value is None else value


def lights_of(doc: Any) -> list[Light]:
    out = []
    params = doc if isinstance(doc, dict) else doc.parameters
    for name in LIGHT_NAMES:
        hidden = bool(params.get(f"{name}.hidden", False))  # switched off in the outliner
        out.append(Light(np.asarray(parameter(doc, f"{name}.position"), dtype=float).reshape(3),
                         np.clip(np.asarray(parameter(doc, f"{name}.color"), dtype=float).reshape(3), 0, 1),
                         0.0 if hidden else max(float(parameter(doc, f"{name}.intensity")), 0.0)))
    return out


def ambient_of(doc: Any) -> np.ndarray:
    return np.asarray(parameter(doc, AMBIENT_PARAMETER), dtype=float).reshape(3)
