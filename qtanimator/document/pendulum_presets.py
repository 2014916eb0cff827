"""The pendulum and spring constants of 2D characters, as document parameters over presets.

Pendulum parameters are document parameters ``"<asset>.pendulum.<name>"`` (see
:class:`qtanimator.core.pendulum.PendulumParams`); :func:`set_pendulum_preset` applies a
named preset (``physical`` or ``handout``). Spring joints' constants are document
parameters ``"<asset>.spring.<name>"``
(:class:`~qtanimator.core.spring_joint.SpringParams`); :func:`set_spring_preset` applies
``soft`` or ``stiff``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from qtanimator.core.pendulum import PRESETS, PendulumParams
from qtanimator.core.spring_joint import SPRING_PRESETS, SpringParams
from qtanimator.document.commands import Command, Macro, SetParameter
from qtanimator.document.document import Document


def _preset_params(doc: Document, prefix: str, presets: Mapping[str, Any], default: str) -> Any:
    """A named preset (``default`` when unset) with the parameters ``prefix + <name>`` over
    it; the preset itself when they do not make valid constants."""
    # list() copies in one step: the simulation worker may read while the UI thread edits.
    values = {k[len(prefix):]: v for k, v in list(doc.parameters.items()) if k.startswith(prefix)}
    preset = presets.get(str(values.pop("preset", default)), presets[default])
    try:
        return type(preset).from_dict({**preset.to_dict(), **values})
    except (TypeError, ValueError):
        return preset


def _preset_command(doc: Document, prefix: str, presets: Mapping[str, Any], name: str, what: str) -> Command:
    """Every parameter ``prefix + <name>`` set to the preset ``name`` (one undo step)."""
    if name not in presets:
        raise ValueError(f"unknown {what.lower()} preset '{name}' (known: {', '.join(presets)})")
    cmds: list[Command] = [SetParameter(doc, prefix + "preset", name)]
    for k, v in presets[name].to_dict().items():
        cmds.append(SetParameter(doc, prefix + k, v))
    return Macro(f"{what} preset: {name}", cmds)


def pendulum_params(doc: Document, asset_id: str) -> PendulumParams:
    """The pendulum constants of a character: its preset (``physical`` when unset) with the
    parameters ``"<asset>.pendulum.<name>"`` over it."""
    params: PendulumParams = _preset_params(doc, f"{asset_id}.pendulum.", PRESETS, "physical")
    return params


def set_pendulum_preset(doc: Document, asset_id: str, name: str) -> Command:
    """Set all of a character's pendulum parameters to a named preset (one undo step)."""
    return _preset_command(doc, f"{asset_id}.pendulum.", PRESETS, name, "Pendulum")


def spring_params(doc: Document, asset_id: str) -> SpringParams:
    """The spring joints' constants of a character: its preset (``soft`` when unset) with
    the parameters ``"<asset>.spring.<name>"`` over it."""
    params: SpringParams = _preset_params(doc, f"{asset_id}.spring.", SPRING_PRESETS, "soft")
    return params


def set_spring_preset(doc: Document, asset_id: str, name: str) -> Command:
    """Set all of a character's spring constants to a named preset (one undo step)."""
    return _preset_command(doc, f"{asset_id}.spring.", SPRING_PRESETS, name, "Spring")
