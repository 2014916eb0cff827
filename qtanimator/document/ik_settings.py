"""The document's IK settings and the solver they pick, for 2D characters and 3D skeletons.

Settings are document parameters ``ik.*`` (defaults in :data:`IK_DEFAULTS`, from the schema
:data:`qtanimator.document.parameters.IK`; edited in the Properties dock, saved with the project):

* ``ik.solver``: ``"dls"`` (damped least squares, the default), ``"ccd"``, ``"fabrik"`` or
  ``"handout"`` (the course handout's gradient descent; 2D only, 3D uses ``dls`` for it);
* ``ik.two_bone``: a chain with exactly two moving joints is solved by the analytic
  two-bone solver whatever ``ik.solver`` says (except ``handout``, which stays the course's);
* ``ik.bend_direction``: the side the two-bone solver bends the middle joint to: ``"keep"``
  (where it bends now), ``"positive"`` / ``"negative"`` (2D: counter-clockwise / clockwise
  on screen). A 3D knee always keeps its side;
* ``ik.freeze_root``, ``ik.max_iterations`` (sweeps or passes for CCD and FABRIK, in 2D and
  3D), ``ik.damping`` (2D DLS), the handout solver's step and count, and the debug arrows'
  scale.

:func:`solve_character` and :func:`solve_skeleton` are the one place each kind of IK drag
turns settings into a solver call.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core import ik, ik3d, ik3d_methods, ik_methods
from qtanimator.core.rig2d import Character
from qtanimator.core.skeleton import Skeleton
from qtanimator.document.document import Document
from qtanimator.document.parameters import IK, IK_SOLVERS, defaults

FloatArray = npt.NDArray[np.float64]

#: IK settings: document parameters with their defaults (a view of the schema,
#: :data:`qtanimator.document.parameters.IK`, which also holds their ranges and labels).
IK_DEFAULTS: dict[str, Any] = defaults(IK)
#: The values ``ik.solver`` takes: ``IK_SOLVERS`` (imported from the schema).
#: The values ``ik.bend_direction`` takes.
BEND_DIRECTIONS = ik_methods.BEND_DIRECTIONS
#: 3D tolerance (scene units) for CCD and FABRIK, as the DLS solver's default.
TOLERANCE_3D = 1e-5


def ik_setting(doc: Document, name: str) -> Any:
    """One IK setting of the document (its default when unset)."""
    return doc.parameter(name, IK_DEFAULTS[name])


def _solver(doc: Document) -> str:
    name = str(ik_setting(doc, "ik.solver"))
    return name if name in IK_SOLVERS else "dls"


def _bend(doc: Document) -> str:
    name = str(ik_setting(doc, "ik.bend_direction"))
    return name if name in BEND_DIRECTIONS else "keep"


def character_solver(doc: Document, character: Character, joint_index: int) -> str:
    """The solver a 2D drag on ``joint_index`` uses: ``"two_bone"`` or ``ik.solver``."""
    solver = _solver(doc)
    if (solver != "handout" and bool(ik_setting(doc, "ik.two_bone"))
            and ik_methods.two_bone_applies(character, joint_index, bool(ik_setting(doc, "ik.freeze_root")))):
        return "two_bone"
    return solver


def solve_character(doc: Document, character: Character, angles: npt.ArrayLike, translation: npt.ArrayLike,
                    joint_index: int, local_point: npt.ArrayLike, target: npt.ArrayLike,
                    limits: ik.Limits = None, stats: ik.IKStats | None = None) -> FloatArray:
    """New local angles (J,) of a 2D character from the document's IK settings."""
    solver = character_solver(doc, character, joint_index)
    freeze_root = bool(ik_setting(doc, "ik.freeze_root"))
    iterations = int(ik_setting(doc, "ik.max_iterations"))
    args = (character, angles, translation, joint_index, local_point, target, limits)
    if solver == "two_bone":
        return ik_methods.solve_two_bone(*args, freeze_root=freeze_root, bend=_bend(doc), stats=stats)
    if solver == "handout":
        return ik.gradient_descent_step(character, angles, translation, joint_index, local_point, target,
                                        step=float(ik_setting(doc, "ik.handout_step")),
                                        iterations=int(ik_setting(doc, "ik.handout_iterations")), limits=limits,
                                        stats=stats)
    if solver == "ccd":
        return ik_methods.solve_ccd(*args, freeze_root=freeze_root, max_iterations=iterations, stats=stats)
    if solver == "fabrik":
        return ik_methods.solve_fabrik(*args, freeze_root=freeze_root, max_iterations=iterations, stats=stats)
    return ik.solve_ik(*args, freeze_root=freeze_root, max_iterations=iterations,
                       damping=float(ik_setting(doc, "ik.damping")), stats=stats)


def skeleton_solver(doc: Document, skeleton: Skeleton, joint: int, dofs: Sequence[ik3d.DofRef],
                    offset: npt.ArrayLike | None = None) -> str:
    """The solver a 3D drag on ``joint`` over ``dofs`` uses: ``"two_bone"``, ``"ccd"``,
    ``"fabrik"`` or ``"dls"`` (also for ``handout``, which has no 3D form). With an
    ``offset`` (a point in ``joint``'s frame) two-bone means ``joint`` and its parent."""
    solver = _solver(doc)
    if (solver != "handout" and bool(ik_setting(doc, "ik.two_bone"))
            and ik3d_methods.two_bone_joints(skeleton, joint, dofs, tip=offset is not None) is not None):
        return "two_bone"
    return solver if solver in ("ccd", "fabrik") else "dls"


def solve_skeleton(doc: Document, skeleton: Skeleton, joint: int, target: npt.ArrayLike,
                   dofs: Sequence[ik3d.DofRef], offset: npt.ArrayLike | None = None) -> ik3d.IKResult:
    """Solve a 3D drag on ``joint`` towards ``target`` over ``dofs`` with the document's
    IK settings (the skeleton's current pose is the start). ``offset``: move that point of
    ``joint``'s frame (a clicked skin point) instead of its origin."""
    solver = skeleton_solver(doc, skeleton, joint, dofs, offset)
    goal = np.asarray(target, dtype=np.float64)
    iterations = int(ik_setting(doc, "ik.max_iterations"))
    if solver == "two_bone":
        return ik3d_methods.solve_two_bone(skeleton, joint, goal, dofs=dofs, tolerance=TOLERANCE_3D,
                                           iterations=iterations, offset=offset)
    if solver == "ccd":
        return ik3d_methods.solve_ccd(skeleton, joint, goal, dofs=dofs, iterations=iterations,
                                      tolerance=TOLERANCE_3D, offset=offset)
    if solver == "fabrik":
        return ik3d_methods.solve_fabrik(skeleton, joint, goal, dofs=dofs, iterations=iterations,
                                         tolerance=TOLERANCE_3D, offset=offset)
    return ik3d.solve_ik(skeleton, joint, goal, dofs=dofs, offset=offset)


__all__ = ["BEND_DIRECTIONS", "IK_DEFAULTS", "IK_SOLVERS", "character_solver", "ik_setting", "skeleton_solver",
           "solve_character", "solve_skeleton"]
