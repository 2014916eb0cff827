"""3D skeletons: joints in depth-first order with three rotational DOFs each.

Conventions (ARCHITECTURE section 4): right-handed, y up, column vectors, float64.

* A joint's local matrix is ``T(offset + translation) · R · S(scale)`` where ``R``
  multiplies the three axis rotations in the skeleton's :attr:`Skeleton.rotation_order`,
  read left to right: ``"zyx"`` (balljoint ``.skel``) is ``Rz(θz)·Ry(θy)·Rx(θx)`` and
  ``"xyz"`` (MIT ``.skel``) is ``Rx·Ry·Rz``. A joint may override the order (BVH gives one
  per joint). Course skeletons only turn (translation 0, scale 1); joints from glTF also
  move and scale (issue 21).
* The pose is always held as Euler DOF values. A joint whose rotation is *keyed* as a
  quaternion (:attr:`Joint.quaternion`, glTF) is interpolated as one by the document, which
  then poses the joint with the equivalent Euler angles: the matrix is the same.
* World matrices: ``W_root = placement · T(root_translation) · L_root``,
  ``W_j = W_parent · L_j``, computed by a depth-first traversal on a
  :class:`~qtanimator.core.matrix_stack.MatrixStack`. Several roots are allowed.
* DOF values are clamped to their limits whenever they are set.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from qtanimator.core.matrix_stack import MatrixStack
from qtanimator.core.rotation import AXES, ROTATION_ORDERS, axis_rotations, rotation_matrices

FloatArray = npt.NDArray[np.float64]

__all__ = [
    "AXES", "DEFAULT_BOXMAX", "DEFAULT_BOXMIN", "DEFAULT_LIMIT", "ROTATION_ORDERS", "Dof", "Joint", "Skeleton",
    "axis_index", "axis_rotations", "rotation_matrices",
]

DEFAULT_LIMIT = 100000.0
DEFAULT_BOXMIN = (-0.1, -0.1, -0.1)
DEFAULT_BOXMAX = (0.1, 0.1, 0.1)


class Dof:
    """One degree of freedom: a value kept inside ``[min, max]``."""

    __slots__ = ("_value", "min", "max")

    def __init__(self, value: float = 0.0, min: float = -DEFAULT_LIMIT, max: float = DEFAULT_LIMIT) -> None:
        if min > max:
            raise ValueError(f"a DOF's minimum {min} is above its maximum {max}")
        self.min = float(min)
        self.max = float(max)
        self._value = 0.0
        self.value = value

    @property
    def value(self) -> float:
        return self._value

    @value.setter
    def value(self, v: float) -> None:
        self._value = self.clamp(v)

    def clamp(self, v: float) -> float:
        v = float(v)
        if math.isnan(v):
            raise ValueError("a DOF value must be a number, got NaN")
        return min(max(v, self.min), self.max)

    def set_limits(self, lo: float, hi: float) -> None:
        if lo > hi:
            raise ValueError(f"a DOF's minimum {lo} is above its maximum {hi}")
        self.min, self.max = float(lo), float(hi)
        self.value = self._value

    def copy(self) -> Dof:
        d = Dof.__new__(Dof)
        d._value, d.min, d.max = self._value, self.min, self.max
        return d

    def __repr__(self) -> str:
        return f"Dof({self._value!r}, {self.min!r}, {self.max!r})"


_ONES = np.ones(3)


def _vec3(v: Sequence[float] | FloatArray) -> FloatArray:
    a = np.array(v, dtype=np.float64).reshape(3)
    return a


@dataclass
class Joint:
    """One joint. ``parent`` is the parent's index in :attr:`Skeleton.joints` or None."""

    name: str
    parent: int | None = None
    offset: FloatArray = field(default_factory=lambda: np.zeros(3))
    dofs: tuple[Dof, Dof, Dof] = field(default_factory=lambda: (Dof(), Dof(), Dof()))
    boxmin: FloatArray = field(default_factory=lambda: np.array(DEFAULT_BOXMIN))
    boxmax: FloatArray = field(default_factory=lambda: np.array(DEFAULT_BOXMAX))
    #: None: use the skeleton's rotation order.
    rotation_order: str | None = None
    #: The pose's translation, added to the offset (0 for joints that only turn).
    translation: FloatArray = field(default_factory=lambda: np.zeros(3))
    #: The pose's scale along the joint's own axes (1 for joints that do not scale).
    scale: FloatArray = field(default_factory=lambda: np.ones(3))
    #: The rotation is keyed as a quaternion (channels qw, qx, qy, qz; glTF) instead of
    #: three Euler angles.
    quaternion: bool = False
    #: The joint has translation channels (tx, ty, tz) besides its rotation.
    translates: bool = False
    #: The joint has scale channels (sx, sy, sz).
    scales: bool = False

    def __post_init__(self) -> None:
        self.offset = _vec3(self.offset)
        self.translation = _vec3(self.translation)
        self.scale = _vec3(self.scale)
        self.boxmin = _vec3(self.boxmin)
        self.boxmax = _vec3(self.boxmax)
        if len(self.dofs) != 3:
            raise ValueError("a joint has exactly three DOFs (x, y, z)")
        self.dofs = (self.dofs[0], self.dofs[1], self.dofs[2])
        if self.rotation_order is not None and self.rotation_order not in ROTATION_ORDERS:
            raise ValueError(f"unknown rotation order {self.rotation_order!r}")

    @property
    def pose(self) -> FloatArray:
        """The three DOF values (x, y, z) as an array."""
        return np.array([d.value for d in self.dofs])

    def copy(self) -> Joint:
        return Joint(self.name, self.parent, self.offset.copy(),
                     (self.dofs[0].copy(), self.dofs[1].copy(), self.dofs[2].copy()),
                     self.boxmin.copy(), self.boxmax.copy(), self.rotation_order, self.translation.copy(),
                     self.scale.copy(), self.quaternion, self.translates, self.scales)


def axis_index(axis: str | int) -> int:
    """``"x" | "y" | "z"`` (or 0, 1, 2) → 0, 1, 2."""
    if isinstance(axis, int) and not isinstance(axis, bool):
        if 0 <= axis <= 2:
            return axis
    elif isinstance(axis, str) and axis.lower() in AXES:
        return AXES.index(axis.lower())
    raise ValueError(f"axis must be 'x', 'y' or 'z', got {axis!r}")


class Skeleton:
    """Joints in depth-first pre-order (every parent precedes its children)."""

    def __init__(self, joints: Sequence[Joint], rotation_order: str = "zyx", name: str = "",
                 dialect: str = "") -> None:
        if rotation_order not in ROTATION_ORDERS:
            raise ValueError(f"unknown rotation order {rotation_order!r}")
        self.joints: list[Joint] = list(joints)
        self.rotation_order = rotation_order
        self.name = name
        #: where the skeleton came from: "balljoint", "mit", "bvh", "gltf" or "".
        self.dialect = dialect
        self.root_translation: FloatArray = np.zeros(3)
        #: A fixed matrix above every root (glTF: the nodes above the skeleton); None: identity.
        self.placement: FloatArray | None = None
        for i, j in enumerate(self.joints):
            if j.parent is not None and not (0 <= j.parent < i):
                raise ValueError(f"joint {i} ({j.name!r}) has parent {j.parent}, which does not precede it")
        self._depths = self._compute_depths()

    def _compute_depths(self) -> list[int]:
        depths: list[int] = []
        for j in self.joints:
            depths.append(0 if j.parent is None else depths[j.parent] + 1)
        return depths

    # ----------------------------------------------------------------- structure
    def __len__(self) -> int:
        return len(self.joints)

    @property
    def num_joints(self) -> int:
        return len(self.joints)

    @property
    def parents(self) -> list[int]:
        """Parent indices with -1 for roots."""
        return [-1 if j.parent is None else j.parent for j in self.joints]

    @property
    def names(self) -> list[str]:
        return [j.name for j in self.joints]

    @property
    def depths(self) -> list[int]:
        return list(self._depths)

    def children(self, index: int) -> list[int]:
        return [i for i, j in enumerate(self.joints) if j.parent == index]

    def index_of(self, name: str) -> int:
        """Index of the first joint called ``name`` (names need not be unique)."""
        for i, j in enumerate(self.joints):
            if j.name == name:
                return i
        raise KeyError(name)

    def joint_keys(self) -> list[str]:
        """Stable per-joint keys: the name, or ``name#index`` where the name is repeated."""
        counts: dict[str, int] = {}
        for j in self.joints:
            counts[j.name] = counts.get(j.name, 0) + 1
        return [j.name if counts[j.name] == 1 else f"{j.name}#{i}" for i, j in enumerate(self.joints)]

    # ---------------------------------------------------------------------- pose
    def dof(self, joint_index: int, axis: str | int) -> Dof:
        return self.joints[joint_index].dofs[axis_index(axis)]

    def set_dof(self, joint_index: int, axis: str | int, value: float) -> float:
        """Set one DOF (clamped to its limits) and return the value it took."""
        d = self.joints[joint_index].dofs[axis_index(axis)]
        d.value = value
        return d.value

    def get_dof(self, joint_index: int, axis: str | int) -> float:
        return self.joints[joint_index].dofs[axis_index(axis)].value

    def dof_values(self) -> FloatArray:
        """(J, 3) array of every joint's x, y, z values."""
        return np.array([[d.value for d in j.dofs] for j in self.joints], dtype=np.float64).reshape(-1, 3)

    def set_dof_values(self, values: npt.ArrayLike) -> None:
        """Set every DOF from a (J, 3) array (each clamped)."""
        v = np.asarray(values, dtype=np.float64).reshape(len(self.joints), 3)
        for j, row in zip(self.joints, v):
            for d, x in zip(j.dofs, row):
                d.value = float(x)

    def dof_limits(self) -> tuple[FloatArray, FloatArray]:
        """(J, 3) minima and maxima."""
        lo = np.array([[d.min for d in j.dofs] for j in self.joints], dtype=np.float64).reshape(-1, 3)
        hi = np.array([[d.max for d in j.dofs] for j in self.joints], dtype=np.float64).reshape(-1, 3)
        return lo, hi

    def set_root_translation(self, xyz: npt.ArrayLike) -> None:
        self.root_translation = _vec3(np.asarray(xyz, dtype=np.float64))

    def reset_pose(self) -> None:
        """Every DOF to 0 (clamped into its limits) and the root translation to 0."""
        for j in self.joints:
            for d in j.dofs:
                d.value = 0.0
        self.root_translation = np.zeros(3)

    def copy(self) -> Skeleton:
        s = Skeleton.__new__(Skeleton)
        s.joints = [j.copy() for j in self.joints]
        s.rotation_order = self.rotation_order
        s.name = self.name
        s.dialect = self.dialect
        s.root_translation = self.root_translation.copy()
        s.placement = None if self.placement is None else self.placement.copy()
        s._depths = list(self._depths)
        return s

    # ---------------------------------------------------------------- matrices
    def local_matrices(self, dof_values: npt.ArrayLike | None = None) -> FloatArray:
        """(J, 4, 4) local matrices ``T(offset + translation)·R·S`` for the current (or given) DOF values."""
        n = len(self.joints)
        angles = self.dof_values() if dof_values is None else np.asarray(dof_values, np.float64).reshape(n, 3)
        out = np.zeros((n, 4, 4))
        out[:, 3, 3] = 1.0
        orders = [j.rotation_order or self.rotation_order for j in self.joints]
        for order in set(orders):
            mask = np.array([o == order for o in orders])
            out[mask, :3, :3] = rotation_matrices(angles[mask], order)
        if n:
            out[:, :3, 3] = np.array([j.offset + j.translation for j in self.joints])
            scaled = [i for i, j in enumerate(self.joints) if not np.array_equal(j.scale, _ONES)]
            if scaled:
                out[scaled, :3, :3] *= np.array([self.joints[i].scale for i in scaled])[:, None, :]
        return out

    def world_matrices(self, dof_values: npt.ArrayLike | None = None,
                       root_translation: npt.ArrayLike | None = None) -> FloatArray:
        """(J, 4, 4) joint-to-world matrices, root translation included.

        The traversal runs on a :class:`MatrixStack`: joints come in depth-first pre-order,
        so before a joint at depth d the stack is popped back to d + 1 matrices.
        """
        local = self.local_matrices(dof_values)
        rt = self.root_translation if root_translation is None else _vec3(np.asarray(root_translation))
        n = len(self.joints)
        world = np.empty((n, 4, 4))
        if n == 0:
            return world
        stack = MatrixStack(max(self._depths) + 3)
        if self.placement is not None:
            stack.load(self.placement)
        stack.translate(float(rt[0]), float(rt[1]), float(rt[2]))
        chain: list[int] = []  # the joint whose world matrix sits at each pushed level
        for i, joint in enumerate(self.joints):
            p = joint.parent
            while chain and chain[-1] != p:
                stack.pop()
                chain.pop()
            if p is not None and not chain:
                # Parents precede children but the order is not depth-first (MIT .skel):
                # continue from the parent's finished world matrix.
                stack.push()
                stack.load(world[p])
                chain.append(p)
            stack.push()
            stack.multiply(local[i])
            chain.append(i)
            world[i] = stack.top
        return world

    def joint_positions(self) -> FloatArray:
        """(J, 3) world positions of the joints."""
        return self.world_matrices()[:, :3, 3].copy()

    def bind_world_matrices(self) -> FloatArray:
        """World matrices with every DOF at 0 and no root translation (the MIT bind pose)."""
        return self.world_matrices(np.zeros((len(self.joints), 3)), np.zeros(3))

    def __repr__(self) -> str:
        return f"Skeleton({len(self.joints)} joints, rotation_order={self.rotation_order!r})"
