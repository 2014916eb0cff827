"""Caches derived from a 2D character live on the character (``Character.derived``), owned by
the document's runtime with it, not in module globals: two characters never share a plan,
and a rebuilt character starts with none."""

from __future__ import annotations

import numpy as np
from test_ik import _random_chain

from qtanimator.core import ik


def test_ik_chain_plans_are_kept_on_their_character() -> None:
    a, b = _random_chain(4, 1), _random_chain(4, 2)
    assert a.derived == {} and b.derived == {}
    angles = np.zeros(len(a.joints))
    ik.solve_ik(a, angles, np.zeros(2), 3, np.zeros(2), np.array([5.0, 5.0]))
    assert set(a.derived["ik.plans"]) == {(3, True)}
    assert "ik.plans" not in b.derived  # nothing shared between characters
    plan = a.derived["ik.plans"][(3, True)]
    ik.solve_ik(a, angles, np.zeros(2), 3, np.zeros(2), np.array([4.0, 6.0]))
    assert a.derived["ik.plans"][(3, True)] is plan  # built once, reused
    ik.solve_ik(a, angles, np.zeros(2), 2, np.zeros(2), np.array([4.0, 6.0]), freeze_root=False)
    assert set(a.derived["ik.plans"]) == {(3, True), (2, False)}
    assert not any(isinstance(v, dict) and a in v for v in vars(ik).values())  # no module-level cache of it
