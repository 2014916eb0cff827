"""The document's IK settings pick the solver of every IK drag, 2D and 3D
(qtanimator.document.ik_settings through character2d.ik_values and character3d.ik_values)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from qtanimator.core import ik, ik3d, ik3d_methods, ik_methods
from qtanimator.core.ik import planar_chain
from qtanimator.document import Document, SetParameter, UndoStack
from qtanimator.document import character2d as c2d
from qtanimator.document import character3d as c3d
from qtanimator.document.commands import AddAsset
from qtanimator.document.document import Asset
from qtanimator.document.ik_settings import IK_DEFAULTS, IK_SOLVERS, character_solver, skeleton_solver

ARM_SKEL = """balljoint root {
  offset 0 0 0
  balljoint shoulder {
    offset 0 1 0
    balljoint elbow {
      offset 1 0 0
      balljoint wrist {
        offset 0.8 0 0
        balljoint hand {
          offset 0.3 0 0
        }
      }
    }
  }
}
"""


def doc2d(links: int) -> tuple[Document, UndoStack, str]:
    doc = Document()
    stack = UndoStack(doc)
    stack.push(AddAsset(Asset("chain", c2d.ASSET_KIND, None, {}), planar_chain(links, 10.0)))
    return doc, stack, "chain"


def angles_after(doc: Document, values: dict[str, float], n: int) -> np.ndarray:
    out = np.asarray(c2d.keyframed_angles(doc, "chain", 0.0), dtype=float).copy()
    for k in range(n):
        cid = c2d.angle_channel_id("chain", f"link{k}")
        if cid in values:
            out[k] = values[cid]
    return out


def set_params(doc: Document, stack: UndoStack, **values: object) -> None:
    for name, value in values.items():
        stack.push(SetParameter(doc, f"ik.{name}", value))


@pytest.mark.parametrize("solver", ["dls", "ccd", "fabrik", "handout"])
def test_2d_ik_values_use_the_solver_setting(solver: str) -> None:
    doc, stack, aid = doc2d(5)
    set_params(doc, stack, solver=solver)
    ch = c2d.character(doc, aid)
    lp, q = np.array([50.0, 0.0]), np.array([30.0, 20.0])
    start = np.zeros(5)
    assert character_solver(doc, ch, 4) == solver
    values = c2d.ik_values(doc, aid, 4, lp, q, 0.0)
    expected = {
        "dls": lambda: ik.solve_ik(ch, start, (0, 0), 4, lp, q, limits=np.tile([-math.inf, math.inf], (5, 1))),
        "ccd": lambda: ik_methods.solve_ccd(ch, start, (0, 0), 4, lp, q),
        "fabrik": lambda: ik_methods.solve_fabrik(ch, start, (0, 0), 4, lp, q),
        "handout": lambda: ik.gradient_descent_step(ch, start, (0, 0), 4, lp, q),
    }[solver]()
    np.testing.assert_allclose(angles_after(doc, values, 5), expected, atol=1e-12)
    if solver != "handout":
        assert ik.ik_error(ch, angles_after(doc, values, 5), (0, 0), 4, lp, q) < 1e-3


def test_2d_two_joint_chains_use_the_two_bone_solver_unless_turned_off() -> None:
    doc, stack, aid = doc2d(3)   # root frozen: two moving joints
    ch = c2d.character(doc, aid)
    lp, q = np.array([30.0, 0.0]), np.array([18.0, 6.0])
    assert IK_DEFAULTS["ik.two_bone"] is True and IK_DEFAULTS["ik.bend_direction"] == "keep"
    for solver in ("dls", "ccd", "fabrik"):
        set_params(doc, stack, solver=solver)
        assert character_solver(doc, ch, 2) == "two_bone"
        values = c2d.ik_values(doc, aid, 2, lp, q, 0.0)
        np.testing.assert_allclose(angles_after(doc, values, 3),
                                   ik_methods.solve_two_bone(ch, np.zeros(3), (0, 0), 2, lp, q), atol=1e-12)
    for bend, sign in (("positive", 1.0), ("negative", -1.0)):
        set_params(doc, stack, bend_direction=bend)
        b = angles_after(doc, c2d.ik_values(doc, aid, 2, lp, q, 0.0), 3)
        assert math.copysign(1.0, b[2]) == sign and ik.ik_error(ch, b, (0, 0), 2, lp, q) < 1e-9
    set_params(doc, stack, two_bone=False, solver="ccd")
    assert character_solver(doc, ch, 2) == "ccd"
    set_params(doc, stack, two_bone=True, solver="handout")   # the course's solver stays the course's
    assert character_solver(doc, ch, 2) == "handout"
    set_params(doc, stack, solver="dls", freeze_root=False)   # the root moves too: three joints
    assert character_solver(doc, ch, 2) == "dls"


@pytest.mark.parametrize("solver", ["ccd", "fabrik", "two_bone"])
def test_2d_ik_drag_respects_joint_limits_and_is_one_undo_step(solver: str) -> None:
    links = 3 if solver == "two_bone" else 5
    doc, stack, aid = doc2d(links)
    set_params(doc, stack, solver="dls" if solver == "two_bone" else solver)
    limits = np.tile([-math.inf, math.inf], (links, 1))
    limits[1:] = (-0.3, 0.3)
    lp = np.array([links * 10.0, 0.0])
    depth = len(stack.done)
    for frac in (0.3, 0.6, 1.0):
        q = np.array([links * 10.0 - 25.0 * frac, 30.0 * frac])
        stack.push(c2d.ik_drag(doc, aid, links - 1, lp, q, 0.0, gesture="drag", limits=limits))
    assert len(stack.done) == depth + 1
    angles = np.asarray(c2d.keyframed_angles(doc, aid, 0.0))
    assert np.all(np.abs(angles[1:]) <= 0.3 + 1e-12) and np.any(angles != 0)
    stack.undo()
    assert not np.any(np.asarray(c2d.keyframed_angles(doc, aid, 0.0)))


@pytest.fixture
def arm3d(tmp_path: Path) -> tuple[Document, UndoStack, str]:
    path = tmp_path / "arm.skel"
    path.write_text(ARM_SKEL)
    doc = Document()
    stack = UndoStack(doc)
    stack.push(c3d.add_character3d_command(doc, path))
    return doc, stack, "arm"


@pytest.mark.parametrize("solver", IK_SOLVERS)
def test_3d_ik_values_use_the_solver_setting(arm3d: tuple[Document, UndoStack, str], solver: str) -> None:
    doc, stack, aid = arm3d
    set_params(doc, stack, solver=solver)
    skel = c3d.character(doc, aid).skeleton
    hand = skel.index_of("hand")
    dofs = ik3d.chain_dofs(skel, hand, 3)
    q = np.array([1.2, 1.9, 0.3])
    assert skeleton_solver(doc, skel, hand, dofs) == ("dls" if solver == "handout" else solver)
    values = c3d.ik_values(doc, aid, hand, q, 0.0, dofs)
    posed = c3d.pose_skeleton(doc, aid, 0.0)
    expected = {"dls": ik3d.solve_ik, "handout": ik3d.solve_ik, "ccd": ik3d_methods.solve_ccd,
                "fabrik": ik3d_methods.solve_fabrik}[solver](posed, hand, q, dofs=dofs)
    assert values == pytest.approx(expected.by_axis_name(), abs=1e-12)
    v = posed.dof_values()
    for (j, axis), x in values.items():
        v[j, "xyz".index(str(axis))] = x
    assert np.linalg.norm(ik3d.end_position(posed, v, hand) - q) < 1e-3


def test_3d_two_joint_chains_use_the_two_bone_solver(arm3d: tuple[Document, UndoStack, str]) -> None:
    doc, stack, aid = arm3d
    skel = c3d.character(doc, aid).skeleton
    wrist = skel.index_of("wrist")
    dofs = ik3d.chain_dofs(skel, wrist, 3)   # shoulder and elbow: the root is left out
    assert {j for j, _a in dofs} == {skel.index_of("shoulder"), skel.index_of("elbow")}
    q = np.array([0.9, 1.8, 0.4])
    for solver in ("dls", "ccd", "fabrik"):
        set_params(doc, stack, solver=solver)
        assert skeleton_solver(doc, skel, wrist, dofs) == "two_bone"
        values = c3d.ik_values(doc, aid, wrist, q, 0.0, dofs)
        expected = ik3d_methods.solve_two_bone(c3d.pose_skeleton(doc, aid, 0.0), wrist, q, dofs=dofs)
        assert values == pytest.approx(expected.by_axis_name(), abs=1e-12) and expected.error < 1e-9
    set_params(doc, stack, two_bone=False)
    assert skeleton_solver(doc, skel, wrist, dofs) == "fabrik"
    # keyed through the command: one undo step
    depth = len(stack.done)
    stack.push(c3d.set_dofs_command(doc, aid, c3d.ik_values(doc, aid, wrist, q, 0.0, dofs), 0.0, gesture="g"))
    stack.push(c3d.set_dofs_command(doc, aid, c3d.ik_values(doc, aid, wrist, q * 1.01, 0.0, dofs), 0.0,
                                    gesture="g"))
    assert len(stack.done) == depth + 1
