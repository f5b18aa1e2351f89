"""swtlab_base.cluster on a real two-worker ``dask.distributed.LocalCluster``: each task runs
numba, OpenCV and BLAS on its share of its host's cores; ``swtlab flow --dask`` (frame
pairs) on the cluster gives the numbers of the local run (the gap bench's campaigns on the
cluster: tests/test_gap_bench.py)."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

from softflow.field_analysis import analyse_frames
from softflow.threads import limit as softflow_limit
from swtlab.pipeline.process import limit_threads
from swtlab_base.cluster import map_in_order, task_slots
from swtlab_cli.main import main
from virtual_testbed.flow_render import FlowScene, render_flow, write_flow_render

distributed = pytest.importorskip("distributed")

pytestmark = pytest.mark.slow  # local Dask clusters started, frames rendered and measured on them


@pytest.fixture(scope="module")
def client():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            yield client


def _limits(_) -> dict:
    """In a task: the threads numba, OpenCV and each loaded BLAS/OpenMP library may use."""
    import cv2
    import numba
    from threadpoolctl import threadpool_info

    return {"numba": numba.get_num_threads(), "opencv": cv2.getNumThreads(),
            "blas": {i["filepath"]: i["num_threads"] for i in threadpool_info()}}


@pytest.mark.parametrize("limit", [limit_threads, softflow_limit], ids=["runs", "frame_pairs"])
@pytest.mark.slow_workers  # restarts the cluster's two worker processes
def test_each_task_runs_on_its_share_of_its_hosts_cores(client, limit):
    """2 one-thread workers on this host: each task gets cores // 2 threads (1 on 2 cores),
    not the thread per core each library starts with; with the runs' limit (``swtlab
    process``) and the frame pairs' (``swtlab flow``)."""
    client.restart()  # fresh workers: each library at its own thread count, as started
    share = max(1, len(os.sched_getaffinity(0)) // 2)
    assert task_slots(client) == {"127.0.0.1": 2}
    seen = list(map_in_order(client, _limits, range(4), limit=limit))
    assert len(seen) == 4
    for limits in seen:
        assert limits["numba"] == share and limits["opencv"] == share
        assert len(limits["blas"]) >= 2 and set(limits["blas"].values()) == {share}


def _fails(x):
    if x == 2:
        raise ValueError(f"task {x} failed")
    return x


def test_results_come_back_in_input_order_and_errors_are_raised(client):
    assert list(map_in_order(client, _fails, [1, 0, 3], limit=limit_threads)) == [1, 0, 3]
    with pytest.raises(ValueError, match="task 2 failed"):
        list(map_in_order(client, _fails, [1, 2], limit=limit_threads))
    assert list(map_in_order(client, _fails, [], limit=limit_threads)) == []


@pytest.fixture(scope="module")
def render():
    """3 frames (2 pairs) of a 320 px scene: the cluster's flow is compared with the local
    one number for number, which holds at any frame size (the default 512 px scene cost 2.6
    times the pixels: 9 s to render, 22 s for the four flows)."""
    scene = FlowScene(size_px=(320, 320), wheel_center_px=(160, 100), wheel_radius_px=64, seed=5)
    return scene, render_flow(scene, 3)


@pytest.mark.slow_render  # three frames rendered (module fixture), four flows measured
@pytest.mark.slow_workers
def test_frame_pairs_on_the_cluster_give_the_local_flow(client, render, tmp_path):
    scene, r = render
    here = analyse_frames(r.frames, r.t_s, scene.px_per_m)
    there = analyse_frames(r.frames, r.t_s, scene.px_per_m, client=client)
    assert here.mean.count.max() == 2 and np.isfinite(here.mean.velocity_px_per_s).any()
    np.testing.assert_array_equal(there.mean.velocity_px_per_s, here.mean.velocity_px_per_s)
    for a, b in zip(there.mean.pair_velocities_px_per_s, here.mean.pair_velocities_px_per_s):
        np.testing.assert_array_equal(a, b)
    write_flow_render(r, tmp_path / "run")
    address = client.scheduler.address
    for name, options in (("here", []), ("there", ["--dask", address])):
        assert main(["flow", str(tmp_path / "run"), "--json", str(tmp_path / name)]
                    + options) == 0
    assert json.loads((tmp_path / "here").read_text())["pairs"] == 2
    assert (tmp_path / "there").read_text() == (tmp_path / "here").read_text()


def test_flow_with_an_unreachable_scheduler_is_one_line_and_exit_3(render, tmp_path, capsys,
                                                                    monkeypatch):
    from swtlab_base import cluster

    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT_S", 1)
    assert main(["flow", str(tmp_path), "--dask", "tcp://127.0.0.1:9"]) == 3
    err = capsys.readouterr().err.strip()
    assert err.startswith("swtlab flow: --dask tcp://127.0.0.1:9: cannot reach")
    assert len(err.splitlines()) == 1
