"""The constants of a character's pendulums (:class:`PendulumParams`, the named :data:`PRESETS`) and the
blow-up check of a simulated state (:func:`check_state`, :class:`PendulumBlowUp`); the
equations and their integration are :mod:`qtanimator.core.pendulum`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from qtanimator.core.rig2d import Character

FloatArray = npt.NDArray[np.float64]

INTEGRATORS = ("symplectic_euler", "leapfrog", "rk4")

#: The smallest internal step (s): 1,667 steps per 60 Hz frame. A step of 1e-9 s would make
#: one frame 16 million steps, a simulation that never ends.
MIN_STEP = 1.0e-5

@dataclass(frozen=True)
class PendulumParams:
    """Simulation constants of one character.

    ``g`` (units/s²) pulls towards +y. ``damping`` is a in ω ← ω·e^(−aτ) (1/s).
    ``restitution`` e (0 … 1) is the share of its speed a joint keeps when it bounces off
    one of its angle limits (0: it stops dead; 1: a perfect bounce).
    ``length_scale`` scales y0 and the chain offsets before anything uses them (the handout's
    1/1000). ``accel_scale`` / ``rotation_accel_scale`` scale the pivot acceleration from the
    root's translation and from keyframed ancestors' rotation. ``inertia`` is ``exact`` or
    ``reference`` (the starter's formulas). ``point_mass_forcing`` uses the handout's 1/L² in
    place of m/I in the forcing term. ``step`` is the fixed internal step in seconds.
    """

    g: float = 3000.0
    damping: float = 0.3
    restitution: float = 0.5
    length_scale: float = 1.0
    accel_scale: float = 1.0
    rotation_accel_scale: float = 1.0
    inertia: str = "exact"
    point_mass_forcing: bool = False
    coupled: bool = True
    integrator: str = "symplectic_euler"
    step: float = 1.0 / 600.0

    def __post_init__(self) -> None:
        if self.inertia not in ("exact", "reference"):
            raise ValueError("inertia must be 'exact' or 'reference'")
        if self.integrator not in INTEGRATORS:
            raise ValueError(f"integrator must be one of {', '.join(INTEGRATORS)}")
        if not (self.step >= MIN_STEP and math.isfinite(self.step)):
            raise ValueError(f"the step must be at least {MIN_STEP:g} s (a frame would take too many steps)")
        for name in ("g", "damping", "length_scale", "accel_scale", "rotation_accel_scale"):
            if not math.isfinite(float(getattr(self, name))):
                raise ValueError(f"{name} must be finite")
        if not 0.0 <= float(self.restitution) <= 1.0:
            raise ValueError("restitution must be between 0 (a joint stops at its limit) and 1 (a perfect bounce)")

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> PendulumParams:
        names = {f.name: f.type for f in fields(cls)}
        kw = {k: v for k, v in d.items() if k in names}
        return replace(cls(), **kw)

#: Named presets. ``physical`` (the default) uses exact moments, per-second units and coupled
#: chains. ``handout`` is the CMU handout's Task 3B: g = 5000, lengths / 1000,
#: rotation acceleration × 10000, damping a = 1, τ = 1/60 s, the starter's moments and the
#: 1/L² forcing. The handout measures accelerations per frame² (at 60 frames per second);
#: our pivot accelerations are per s², hence the 1/3600 factors.
PRESETS: dict[str, PendulumParams] = {
    "physical": PendulumParams(),
    "handout": PendulumParams(g=5000.0, damping=1.0, length_scale=0.001, accel_scale=1.0 / 3600.0,
                              rotation_accel_scale=10000.0 / 3600.0, inertia="reference",
                              point_mass_forcing=True, coupled=False, step=1.0 / 60.0),
    # Task 3A: θ'' = −m g L sin θ / I with g = 3, no pivot acceleration.
    "handout_3a": PendulumParams(g=3.0, damping=1.0, accel_scale=0.0, rotation_accel_scale=0.0,
                                 inertia="reference", coupled=False, step=1.0 / 60.0),
}

#: Angular speeds above this (rad/s, about 160 turns per second) count as a blow-up even
#: while the numbers are still finite: no pendulum an animator keys swings that fast.
RUNAWAY_RATE = 1.0e3

class PendulumBlowUp(RuntimeError):
    """A pendulum simulation went unstable at ``time`` (s); ``parameter`` names the setting
    to change first, ``joint`` the joint that ran away."""

    def __init__(self, message: str, parameter: str, time: float, joint: str) -> None:
        super().__init__(message)
        self.message = message
        self.parameter = parameter
        self.time = time
        self.joint = joint

def check_state(character: Character, params: PendulumParams, theta: FloatArray, omega: FloatArray,
                time: float) -> PendulumBlowUp | None:
    """The blow-up the state ``(theta, omega)`` at ``time`` shows, or None if it is sound:
    a non-finite angle or rate, or a rate beyond :data:`RUNAWAY_RATE`. The message says
    what to change: a negative damping pumps energy in; otherwise the fixed step is too
    large for the forces and the integrator is unstable."""
    bad = ~(np.isfinite(theta) & np.isfinite(omega)) | (np.abs(np.nan_to_num(omega, nan=np.inf)) > RUNAWAY_RATE)
    if not bad.any():
        return None
    k = int(np.flatnonzero(bad)[0])
    name = character.joints[k].name
    if params.damping < 0:
        parameter, advice = "damping", "the damping is negative, which adds energy every step; make it 0 or more"
    else:
        parameter, advice = "step", (f"the step of {params.step:g} s is too large for gravity "
                                     f"{params.g:g} and these accelerations; use a smaller step, more damping "
                                     "or a weaker gravity")
    what = "not a finite number" if not (np.isfinite(theta[k]) and np.isfinite(omega[k])) else \
        f"spinning at {abs(float(omega[k])):.3g} rad/s"
    return PendulumBlowUp(f"the pendulum '{name}' blew up at {time:.3f} s ({what}): {advice}.",
                          parameter, time, name)
