"""``qtanimator render --jobs N`` and ``--dask``: frames equal a single-process render byte for byte."""

from __future__ import annotations

from pathlib import Path

import pytest
from needs import missing

from qtanimator.render.cli_render import render_main

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def _render(scene: Path, out: Path, *extra: str) -> dict[str, bytes]:
    assert render_main([str(scene), "-o", str(out), "--frames", "0:29", "--size", "120x90", "--quiet",
                        *extra]) == 0
    return {p.name: p.read_bytes() for p in sorted(out.iterdir())}


@pytest.mark.parametrize("scene", ["pendulum_clock.svg", "demo/demo.qtanim"])
def test_jobs_2_frames_equal_single_process(qapp, tmp_path: Path, scene: str) -> None:  # type: ignore[no-untyped-def]
    one = _render(SCENES / scene, tmp_path / "one", "--jobs", "1")
    two = _render(SCENES / scene, tmp_path / "two", "--jobs", "2")
    assert len(one) == 30 and one == two


def test_jobs_2_gif_equals_single_process(qapp, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """A GIF is encoded from raw frames in the parent (the workers encode only PNG frames)."""
    outs = []
    for jobs in ("1", "2"):
        out = tmp_path / f"clock{jobs}.gif"
        assert render_main([str(SCENES / "pendulum_clock.svg"), "-o", str(out), "--frames", "0:29", "--size",
                            "120x90", "--quiet", "--jobs", jobs]) == 0
        outs.append(out.read_bytes())
    assert outs[0] == outs[1]


def test_pendulums_are_baked_in_the_parent(qapp, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    from qtanimator.document.character2d import simulation
    from qtanimator.render import parallel
    from qtanimator.render.cli_render import load_scene

    doc = load_scene(SCENES / "pendulum_clock.svg")
    times = [f / doc.fps for f in range(20)]
    specs = parallel.chunk_specs(str(SCENES / "pendulum_clock.svg"), doc, times, (60, 40), "white", 3)
    assert [len(s.times) for s in specs] == [7, 6, 7] and sum((s.times for s in specs), ()) == tuple(times)
    states = specs[0].states
    assert states and all(theta.shape[0] >= 20 for theta, _omega, _p in states.values())
    fresh = load_scene(SCENES / "pendulum_clock.svg")
    cache = simulation(fresh)
    cache.load_baked_states(states)
    before = cache.steps_taken
    aid = next(iter(states))
    assert (cache.state(aid, 19)[0] == simulation(doc).state(aid, 19)[0]).all()
    assert cache.steps_taken == before  # read from the baked frames, never simulated again


def test_jobs_must_be_positive(qapp, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    assert render_main([str(SCENES / "pendulum_clock.svg"), "-o", str(tmp_path / "f"), "--jobs", "0"]) == 1
    assert "--jobs" in capsys.readouterr().err


def test_dask_local_cluster_frames_equal_single_process(qapp, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """The 2D and the 3D view (the demo: a walker with a cape, a flag, an arm) on one cluster."""
    try:
        import distributed
    except ImportError:  # a test dependency (pyproject's test extra): in CI this fails
        missing("the 'distributed' package is not installed")
    one = _render(SCENES / "pendulum_clock.svg", tmp_path / "one", "--jobs", "1")
    one_3d = _render(DEMO, tmp_path / "one3d", "--jobs", "1", *VIEW_3D)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        dask = _render(SCENES / "pendulum_clock.svg", tmp_path / "dask", "--dask", cluster.scheduler_address)
        dask_3d = _render(DEMO, tmp_path / "dask3d", "--dask", cluster.scheduler_address, *VIEW_3D)
    assert len(one) == 30 and one == dask
    assert len(one_3d) == 12 and one_3d == dask_3d


DEMO = SCENES / "demo" / "demo.qtanim"
VIEW_3D = ("--view", "3d", "--frames", "0:11", "--size", "96x72")


def test_3d_jobs_2_frames_equal_single_process(qapp, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    one = _render(DEMO, tmp_path / "one", "--jobs", "1", *VIEW_3D)
    two = _render(DEMO, tmp_path / "two", "--jobs", "2", *VIEW_3D)
    assert len(one) == 12 and one == two
    assert len(set(one.values())) > 6  # the frames move (the cloth and the walker), so order matters


def test_3d_cloth_is_baked_in_the_parent(qapp) -> None:  # type: ignore[no-untyped-def]
    """The workers get each cloth's positions at their frames and never simulate."""
    from qtanimator.document import cloth
    from qtanimator.render import parallel
    from qtanimator.render.cli_render import load_scene

    doc = load_scene(DEMO)
    times = [f / doc.fps for f in range(9)]
    specs = parallel.chunk_specs_3d(str(DEMO), doc, times, (60, 40), None, 3)
    assert [s.times for s in specs] == [tuple(times[0:3]), tuple(times[3:6]), tuple(times[6:9])]
    cloths = [a.id for a in doc.assets.values() if a.kind == cloth.ASSET_KIND]
    assert cloths and set(specs[1].cloth) == set(cloths)
    aid = cloths[0]
    assert sorted(specs[1].cloth[aid]) == [3, 4, 5]  # cache slots of frames 3-5 (the range starts at 0)
    fresh = load_scene(DEMO)
    cache = cloth.cloth_cache(fresh, aid)
    cache.load_baked(specs[1].cloth[aid])
    for f in (3, 4, 5):
        assert (cache.positions(f) == cloth.cloth_state(doc, aid, f)).all()
        assert not (cache.positions(f) == cache.frames[0]).all()  # a moved frame, not the rest state
    assert cache.cached_frames == 1  # only the rest state: nothing simulated
