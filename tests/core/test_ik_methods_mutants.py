"""2D CCD / FABRIK helpers (core/ik_methods.py): the pattern move's parabola vertex, and
the iteration count of a solve that has nothing to do."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qtanimator.core.ik import IKStats, planar_chain
from qtanimator.core.ik_methods import _extrapolate, solve_fabrik


class _LineChain:
    """A stand-in chain whose tip is (delta[0], 0): the error at factor f along a step is
    |target - f·step| exactly, so the squared error is a parabola in f."""

    def evaluate(self, delta):
        d = np.asarray(delta, dtype=np.float64)
        return None, np.zeros((1, 2)), np.array([d[0], 0.0])


def test_pattern_move_lands_on_the_parabola_vertex():
    # Target x = 3, sweep from 0 to 1: factors 1, 2, 4 give errors 2, 1, 1 (4 is no better
    # than 2, so doubling stops). The squared errors 4, 1, 1 at f = 1, 2, 4 lie on
    # (f - 3)², whose vertex f = 3 hits the target exactly.
    inf = np.full(1, math.inf)
    cand, _piv, tip, err = _extrapolate(_LineChain(), np.zeros(1), np.ones(1), 2.0,
                                        np.array([3.0, 0.0]), -inf, inf, np.zeros(1))
    assert cand[0] == pytest.approx(3.0, abs=1e-12)
    assert err == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(tip, [3.0, 0.0], atol=1e-12)


def test_pattern_move_vertex_off_centre():
    # Target x = 2.5: errors at f = 1, 2, 4 are 1.5, 0.5, 1.5; squared 2.25, 0.25, 2.25
    # lie on (f - 2.5)², vertex 2.5.
    inf = np.full(1, math.inf)
    cand, _piv, _tip, err = _extrapolate(_LineChain(), np.zeros(1), np.ones(1), 1.5,
                                         np.array([2.5, 0.0]), -inf, inf, np.zeros(1))
    assert cand[0] == pytest.approx(2.5, abs=1e-12)
    assert err == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("accelerate", [True, False])
def test_fabrik_at_the_target_runs_no_iteration(accelerate):
    ch = planar_chain(3, 50.0)
    a0 = np.array([0.0, 0.2, -0.1])
    stats = IKStats()
    # the point's own position at a0: x along the links, found by forward kinematics
    tip = ch.pose(a0, (0.0, 0.0)).to_world(2, [150.0, 0.0])
    out = solve_fabrik(ch, a0, (0.0, 0.0), 2, [150.0, 0.0], tip, stats=stats, accelerate=accelerate)
    assert stats.iterations == 0
    np.testing.assert_array_equal(out, a0)


def test_fabrik_counts_its_iterations():
    ch = planar_chain(3, 50.0)
    stats = IKStats()
    solve_fabrik(ch, np.zeros(3), (0.0, 0.0), 2, [150.0, 0.0], [60.0, 80.0], stats=stats,
                 max_iterations=1, accelerate=False, tolerance=1e-12)
    assert stats.iterations == 1
