"""Rotations: quaternions, Euler angles and matrices, in one place.

Conventions (ARCHITECTURE section 4): right-handed, column vectors, float64.

* Quaternions are ``(x, y, z, w)`` arrays (glTF's order), unit length where they stand for
  a rotation. ``q`` and ``−q`` are the same rotation.
* Euler angles are ``(x, y, z)`` angles in radians; ``order`` ``"abc"`` means the matrix
  ``R_a(θa) · R_b(θb) · R_c(θc)`` (``"zyx"``: ``Rz·Ry·Rx``, the balljoint order).
* :func:`slerp` is the glTF 2.0 specification's: the shortest path (the second key is
  negated when the two keys' dot product is negative).

Everything is vectorised over leading axes.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]

AXES = ("x", "y", "z")
ROTATION_ORDERS = ("xyz", "xzy", "yxz", "yzx", "zxy", "zyx")
IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])

__all__ = [
    "AXES", "IDENTITY", "ROTATION_ORDERS", "axis_quaternions", "axis_rotations", "euler_filter",
    "euler_from_matrices", "euler_quaternions_with_rates", "euler_to_quaternions", "matrices_to_quaternions",
    "normalize", "polar", "quaternion_conjugate", "quaternion_multiply", "quaternion_to_matrix",
    "quaternions_to_euler", "rotation_matrices", "same_hemisphere", "slerp", "trs_matrix",
]


# ------------------------------------------------------------------------ Euler angles
def axis_rotations(axis: int, angles: npt.ArrayLike) -> FloatArray:
    """(N, 3, 3) right-handed rotations about x (0), y (1) or z (2) by ``angles`` radians."""
    a = np.asarray(angles, dtype=np.float64).reshape(-1)
    c, s = np.cos(a), np.sin(a)
    r = np.zeros((a.shape[0], 3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    r[:, axis, axis] = 1.0
    r[:, i, i] = c
    r[:, j, j] = c
    r[:, i, j] = -s
    r[:, j, i] = s
    return r


def rotation_matrices(angles: npt.ArrayLike, order: str) -> FloatArray:
    """(N, 3) angles (x, y, z) → (N, 3, 3) rotations, the axis factors multiplied in ``order``."""
    if order not in ROTATION_ORDERS:
        raise ValueError(f"unknown rotation order {order!r}")
    a = np.asarray(angles, dtype=np.float64).reshape(-1, 3)
    i, j, k = (AXES.index(ch) for ch in order)
    result: FloatArray = axis_rotations(i, a[:, i]) @ axis_rotations(j, a[:, j]) @ axis_rotations(k, a[:, k])
    return result


def euler_from_matrices(r: npt.ArrayLike, order: str) -> FloatArray:
    """(N, 3, 3) rotations → (N, 3) angles (x, y, z) with ``r = R_a·R_b·R_c`` for ``order`` "abc".

    The middle angle lies in [−π/2, π/2]. At gimbal lock (middle angle ±π/2) the whole turn
    about the shared axis goes on the first axis. The middle angle is taken with ``atan2``
    (not ``asin``), which keeps full precision next to the lock.
    """
    m = np.asarray(r, dtype=np.float64).reshape(-1, 3, 3)
    a, b, c = (AXES.index(ch) for ch in order)
    # r = Ra·Rb·Rc: the standard Tait–Bryan extraction, signed by the order's parity.
    sign = 1.0 if (b - a) % 3 == 1 else -1.0
    sb = np.clip(sign * m[:, a, c], -1.0, 1.0)
    cb = np.hypot(m[:, a, a], m[:, a, b])
    angle_b = np.arctan2(sb, cb)
    angle_a = np.arctan2(-sign * m[:, b, c], m[:, c, c])
    angle_c = np.arctan2(-sign * m[:, a, b], m[:, a, a])
    lock = cb < 1e-12
    if np.any(lock):
        angle_c = np.where(lock, 0.0, angle_c)
        angle_a = np.where(lock, np.arctan2(sign * m[:, c, b], m[:, b, b]), angle_a)
    out = np.zeros((len(m), 3))
    out[:, a], out[:, b], out[:, c] = angle_a, angle_b, angle_c
    return out


def euler_filter(angles: npt.ArrayLike, order: str) -> FloatArray:
    """(T, 3) Euler angles over time → the same rotations as a continuous curve.

    Blender's Euler filter: each sample is replaced by whichever of its two equivalent
    triples (``(a, b, c)`` and ``(a + π, π − b, c + π)`` in the order's axes) is closer to
    the previous sample, then every angle is moved by whole turns towards it.
    """
    e = np.array(angles, dtype=np.float64).reshape(-1, 3)
    if len(e) < 2:
        return e
    a, b, c = (AXES.index(ch) for ch in order)
    two_pi = 2.0 * np.pi
    for k in range(1, len(e)):
        prev = e[k - 1]
        best = None
        for cand in (e[k].copy(), _flipped(e[k], a, b, c)):
            cand = cand + two_pi * np.round((prev - cand) / two_pi)
            dist = float(np.abs(cand - prev).sum())
            if best is None or dist < best[0]:
                best = (dist, cand)
        assert best is not None
        e[k] = best[1]
    return e


def _flipped(e: FloatArray, a: int, b: int, c: int) -> FloatArray:
    f = e.copy()
    f[a] += np.pi
    f[b] = np.pi - f[b]
    f[c] += np.pi
    return f


# ------------------------------------------------------------------------ quaternions
def normalize(q: npt.ArrayLike) -> FloatArray:
    """(…, 4) quaternions scaled to unit length (a zero quaternion stays zero)."""
    a = np.asarray(q, dtype=np.float64)
    n = np.linalg.norm(a, axis=-1, keepdims=True)
    result: FloatArray = a / np.where(n > 0, n, 1.0)
    return result


def quaternion_to_matrix(q: npt.ArrayLike) -> FloatArray:
    """(…, 4) unit quaternions ``(x, y, z, w)`` → (…, 3, 3) rotation matrices."""
    a = np.asarray(q, dtype=np.float64)
    x, y, z, w = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    out = np.empty(a.shape[:-1] + (3, 3))
    out[..., 0, 0] = 1 - 2 * (y * y + z * z)
    out[..., 0, 1] = 2 * (x * y - z * w)
    out[..., 0, 2] = 2 * (x * z + y * w)
    out[..., 1, 0] = 2 * (x * y + z * w)
    out[..., 1, 1] = 1 - 2 * (x * x + z * z)
    out[..., 1, 2] = 2 * (y * z - x * w)
    out[..., 2, 0] = 2 * (x * z - y * w)
    out[..., 2, 1] = 2 * (y * z + x * w)
    out[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return out


def matrices_to_quaternions(m: npt.ArrayLike) -> FloatArray:
    """(…, 3, 3) rotation matrices → (…, 4) unit quaternions with ``w ≥ 0`` (Shepperd's method:
    the largest of the four diagonal combinations is the pivot, so no precision is lost)."""
    r = np.asarray(m, dtype=np.float64)
    shape = r.shape[:-2]
    r = r.reshape(-1, 3, 3)
    t = np.stack([r[:, 0, 0] - r[:, 1, 1] - r[:, 2, 2], -r[:, 0, 0] + r[:, 1, 1] - r[:, 2, 2],
                  -r[:, 0, 0] - r[:, 1, 1] + r[:, 2, 2], r[:, 0, 0] + r[:, 1, 1] + r[:, 2, 2]], axis=1)
    k = np.argmax(t, axis=1)
    q = np.empty((len(r), 4))
    s = np.sqrt(np.maximum(1.0 + t[np.arange(len(r)), k], 0.0)) * 2.0  # 4·|q_k|
    for pivot in range(4):
        sel = k == pivot
        if not np.any(sel):
            continue
        rr, ss = r[sel], s[sel]
        if pivot == 0:
            q[sel] = np.stack([0.25 * ss, (rr[:, 0, 1] + rr[:, 1, 0]) / ss, (rr[:, 0, 2] + rr[:, 2, 0]) / ss,
                               (rr[:, 2, 1] - rr[:, 1, 2]) / ss], axis=1)
        elif pivot == 1:
            q[sel] = np.stack([(rr[:, 0, 1] + rr[:, 1, 0]) / ss, 0.25 * ss, (rr[:, 1, 2] + rr[:, 2, 1]) / ss,
                               (rr[:, 0, 2] - rr[:, 2, 0]) / ss], axis=1)
        elif pivot == 2:
            q[sel] = np.stack([(rr[:, 0, 2] + rr[:, 2, 0]) / ss, (rr[:, 1, 2] + rr[:, 2, 1]) / ss, 0.25 * ss,
                               (rr[:, 1, 0] - rr[:, 0, 1]) / ss], axis=1)
        else:
            q[sel] = np.stack([(rr[:, 2, 1] - rr[:, 1, 2]) / ss, (rr[:, 0, 2] - rr[:, 2, 0]) / ss,
                               (rr[:, 1, 0] - rr[:, 0, 1]) / ss, 0.25 * ss], axis=1)
    q = normalize(q)
    q *= np.where(q[:, 3:4] < 0, -1.0, 1.0)
    return q.reshape(shape + (4,))


def quaternion_multiply(a: npt.ArrayLike, b: npt.ArrayLike) -> FloatArray:
    """Hamilton product of (…, 4) ``(x, y, z, w)`` quaternions: the rotation ``a`` after ``b``."""
    p = np.asarray(a, dtype=np.float64)
    q = np.asarray(b, dtype=np.float64)
    x1, y1, z1, w1 = p[..., 0], p[..., 1], p[..., 2], p[..., 3]
    x2, y2, z2, w2 = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack([
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
    ], axis=-1)


def quaternion_conjugate(q: npt.ArrayLike) -> FloatArray:
    """(…, 4) → the inverse rotation of unit quaternions."""
    out = np.array(q, dtype=np.float64)
    out[..., :3] *= -1.0
    return out


def same_hemisphere(q: npt.ArrayLike, reference: npt.ArrayLike) -> FloatArray:
    """``q`` or ``−q``, whichever has a non-negative dot product with ``reference``."""
    a = np.asarray(q, dtype=np.float64)
    d = np.sum(a * np.asarray(reference, dtype=np.float64), axis=-1, keepdims=True)
    result: FloatArray = np.where(d < 0, -a, a)
    return result


def slerp(a: npt.ArrayLike, b: npt.ArrayLike, u: npt.ArrayLike) -> FloatArray:
    """Shortest-path spherical interpolation of (…, 4) unit quaternions at ``u`` in [0, 1]
    (the glTF 2.0 specification's; nearly equal keys are interpolated linearly and
    normalised, where the sine formula loses precision)."""
    p = np.asarray(a, dtype=np.float64)
    q = np.asarray(b, dtype=np.float64)
    uu = np.asarray(u, dtype=np.float64)[..., None]
    d = np.sum(p * q, axis=-1, keepdims=True)
    q = np.where(d < 0, -q, q)
    d = np.abs(d)
    theta = np.arccos(np.clip(d, -1.0, 1.0))
    s = np.sin(theta)
    near = d > 0.9995
    safe = np.where(near, 1.0, s)
    wa = np.where(near, 1.0 - uu, np.sin((1.0 - uu) * theta) / safe)
    wb = np.where(near, uu, np.sin(uu * theta) / safe)
    out = wa * p + wb * q
    result: FloatArray = np.where(near, normalize(out), out)
    return result


def euler_to_quaternions(angles: npt.ArrayLike, order: str) -> FloatArray:
    """(N, 3) Euler angles → (N, 4) unit quaternions (``w ≥ 0``)."""
    return matrices_to_quaternions(rotation_matrices(angles, order))


def quaternions_to_euler(q: npt.ArrayLike, order: str) -> FloatArray:
    """(N, 4) unit quaternions → (N, 3) Euler angles (see :func:`euler_from_matrices`)."""
    return euler_from_matrices(quaternion_to_matrix(np.asarray(q, dtype=np.float64).reshape(-1, 4)), order)


def axis_quaternions(angles: FloatArray, axis: int) -> FloatArray:
    """(…) angles (radians) → (…, 4) quaternions of the rotations about x (0), y (1) or z (2)."""
    q = np.zeros(angles.shape + (4,))
    q[..., axis] = np.sin(angles / 2)
    q[..., 3] = np.cos(angles / 2)
    return q


def euler_quaternions_with_rates(angles: FloatArray, rates: FloatArray | None,
                                 order: str) -> tuple[FloatArray, FloatArray | None]:
    """Quaternions (and their time derivatives) of ``R_a(θa)·R_b(θb)·R_c(θc)`` for ``order``
    ``"abc"``; ``angles`` and ``rates`` are (..., 3) in x, y, z order.

    The product of the three axis quaternions, signs as they come (unlike
    :func:`euler_to_quaternions`, which goes through the matrix and returns ``w ≥ 0``), so the
    derivative ``dq`` (from ``rates``, by the product rule) is that of ``q`` itself.
    """
    axes = ["xyz".index(c) for c in order]
    qs = [axis_quaternions(angles[..., a], a) for a in axes]
    q = quaternion_multiply(quaternion_multiply(qs[0], qs[1]), qs[2])
    if rates is None:
        return q, None
    dqs = []
    for a in axes:
        half = angles[..., a] / 2
        d = np.zeros(angles.shape[:-1] + (4,))
        d[..., a] = 0.5 * np.cos(half) * rates[..., a]
        d[..., 3] = -0.5 * np.sin(half) * rates[..., a]
        dqs.append(d)
    dq = (quaternion_multiply(quaternion_multiply(dqs[0], qs[1]), qs[2])
          + quaternion_multiply(quaternion_multiply(qs[0], dqs[1]), qs[2])
          + quaternion_multiply(quaternion_multiply(qs[0], qs[1]), dqs[2]))
    return q, dq


# ------------------------------------------------------------------------ matrices
def trs_matrix(translation: npt.ArrayLike, rotation: npt.ArrayLike, scale: npt.ArrayLike) -> FloatArray:
    """(…, 4, 4) ``T · R · S`` from (…, 3), (…, 4) quaternion and (…, 3) arrays."""
    t = np.asarray(translation, dtype=np.float64)
    r = quaternion_to_matrix(rotation)
    s = np.asarray(scale, dtype=np.float64)
    out = np.zeros(t.shape[:-1] + (4, 4))
    out[..., :3, :3] = r * s[..., None, :]
    out[..., :3, 3] = t
    out[..., 3, 3] = 1.0
    return out


def polar(m: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
    """(…, 3, 3) → rotation ``R`` and symmetric stretch ``P`` with ``m = R · P``."""
    a = np.asarray(m, dtype=np.float64)
    u, _s, vt = np.linalg.svd(a)
    d = np.sign(np.linalg.det(u @ vt))
    u = u.copy()
    u[..., :, 2] *= d[..., None]
    r = u @ vt
    return r, np.swapaxes(r, -1, -2) @ a
