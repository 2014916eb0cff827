"""glTF export of MIT Model1 at 20 random poses (issue 15, item 2).

MIT Model1 (``.skel`` + ``.obj`` + ``.attach``, up to 13 influences a vertex, all kept) is keyed at
20 random poses (every joint's DOFs drawn within their limits, a fixed seed), exported with
``import3d.export_gltf``, checked by the Khronos validator (no error) and evaluated
*independently* by ``tests/gltf_spec.py`` (the glTF 2.0 specification's node, animation and
skinning rules, no qtanimator code) at the key times and compared with the program's own
skinning (``character3d.skinned_mesh``), to 1e-4 of the model's size (the rest mesh's
bounding-box diagonal).

Model1's weights do not sum to 1 (the sums lie in [0.9996, 1.0003]); glTF requires unit sums,
so the export divides each vertex's weights by their sum S. Linear blend skinning is linear in
the weights, so the export's vertex is exactly the program's vertex divided by S: that is the
check to 1e-4 of the size. The raw difference (up to |1 − 1/S| times the vertex's distance from
the origin, about 2.6e-4 of the size at these poses) is bounded by that as well.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import gltf_spec
import gltf_validator
import numpy as np
from docfix import set_parameters

from qtanimator.document import Document, UndoStack
from qtanimator.document.character3d import character, set_dofs_command, skinned_mesh
from qtanimator.document.import3d import export_gltf, import_file

#: Positions may differ by this fraction of the model's size.
TOLERANCE = 1e-4
POSES = 20
#: Frames between two posed keys.
STEP = 3
#: Random joint angles are drawn from [-SPREAD, SPREAD] radians, clipped to the DOF's limits.
SPREAD = 1.0


def test_model1_random_poses_match_independent_skinning(shared_data: Path, tmp_path: Path) -> None:
    doc = Document()
    stack = UndoStack(doc)
    imp = import_file(doc, shared_data / "mit6837" / "Model1.skel")
    stack.push(imp.command)
    aid = imp.asset_id
    ch = character(doc, aid)
    assert ch.skin is not None and ch.skin.binding.max_influences == 13
    skel = ch.skeleton
    rng = np.random.default_rng(15)
    times = [doc.frame_to_time(k * STEP) for k in range(POSES)]
    for t in times:
        values: dict[tuple[int | None, str | int], float] = {}
        for j, joint in enumerate(skel.joints):
            for a, dof in enumerate(joint.dofs):
                lo, hi = max(dof.min, -SPREAD), min(dof.max, SPREAD)
                values[(j, a)] = float(rng.uniform(lo, hi)) if lo < hi else dof.clamp(0.0)
        stack.push(set_dofs_command(doc, aid, values, t))
    set_parameters(doc, {"frame_start": 0, "frame_end": (POSES - 1) * STEP})

    out = tmp_path / "model1_poses.glb"
    result, _messages = export_gltf(doc, aid, out)
    report = gltf_validator.validate(out)
    assert not report.errors, "; ".join(str(e) for e in report.errors[:10])
    for issue in report.warnings:
        warnings.warn(f"glTF validator {report.version}, {out.name}: {issue}", stacklevel=1)

    size = float(np.linalg.norm(np.ptp(ch.skin.positions, axis=0)))
    assert size > 0
    assert gltf_spec.model_size(out) <= size * (1 + 1e-6) + 1e-9  # the rest mesh as written
    assert len(gltf_spec.animation_names(out)) >= 1
    limit = TOLERANCE * size
    sums = ch.skin.binding.weight_sums()
    assert sums.shape == (ch.skin.num_vertices,) and np.all(np.abs(sums - 1.0) < 1e-3)
    distinct = []
    for t in times:
        want = skinned_mesh(doc, aid, t)[0]
        (got,) = gltf_spec.world_positions(out, 0, t - times[0])
        assert got.shape == want.shape
        err = float(np.abs(got - want / sums[:, None]).max())
        assert err <= limit, f"t={t:.4f}: positions off by {err:.3g} (limit {limit:.3g})"
        # Against the raw (not renormalised) skinning: only the weight sums' share apart.
        raw = np.linalg.norm(got - want, axis=1)
        assert np.all(raw <= np.abs(1.0 - 1.0 / sums) * np.linalg.norm(want, axis=1) + limit), t
        distinct.append(want)
    # The poses really differ from each other (the test would be vacuous otherwise).
    assert min(float(np.abs(distinct[i] - distinct[i + 1]).max()) for i in range(POSES - 1)) > 10 * limit
    assert len(result.times) >= POSES
