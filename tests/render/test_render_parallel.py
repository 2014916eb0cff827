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
    try:
        import distributed
    except ImportError:  # a test dependency (pyproject's test extra): in CI this fails
        missing("the 'distributed' package is not installed")
    one = _render(SCENES / "pendulum_clock.svg", tmp_path / "one", "--jobs", "1")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        dask = _render(SCENES / "pendulum_clock.svg", tmp_path / "dask", "--dask", cluster.scheduler_address)
    assert len(one) == 30 and one == dask


def test_3d_view_refuses_jobs(qapp, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    rc = render_main([str(SCENES / "arm3d" / "arm3d.qtanim"), "-o", str(tmp_path / "f"), "--frames", "0:1",
                      "--view", "3d", "--jobs", "2"])
    err = capsys.readouterr().err
    assert rc in (1, 2) and len(err.strip().splitlines()) == 1
