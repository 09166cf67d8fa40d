"""penumbra.distributed on a real two-node local Ray cluster (head + worker on loopback, one CPU
each): chunked renders merge exactly, a sweep returns its table, a killed worker's chunk is
retried and the image is still exact."""

import os
import pathlib
import signal
import threading
import time

import numpy as np
import pytest

import penumbra

# Every Ray process of this test on loopback: without this Ray swaps 127.0.0.1 for the
# machine's routable address ("remotely reachable"), and this machine's tests send traffic to
# loopback only. Ray reads it at import, and the cluster's processes inherit it.
os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"

ray = pytest.importorskip("ray") if not os.environ.get("CI") else __import__("ray")
from ray.cluster_utils import Cluster  # noqa: E402

from penumbra import distributed  # noqa: E402

RES = (64, 48)


@pytest.fixture(scope="module")
def cluster():
    """Head and a second node, both on 127.0.0.1 with one CPU: the processes are this
    fixture's own (Cluster keeps them and ends them by handle on shutdown)."""
    loop = dict(node_ip_address="127.0.0.1", num_cpus=1, object_store_memory=80 * 2**20)
    c = Cluster(initialize_head=True, head_node_args=dict(loop, include_dashboard=False))
    c.add_node(**loop)
    c.wait_for_nodes()
    ray.init(address=c.address, _node_ip_address="127.0.0.1", log_to_driver=False)
    nodes = [n["NodeID"] for n in ray.nodes() if n["Alive"]]
    assert len(nodes) == 2
    # One task pinned to each node: penumbra imports there, and each node has a warm worker
    # (a node's first worker takes seconds to start; short chunks would all go elsewhere).
    from ray.util.scheduling_strategies import NodeAffinitySchedulingStrategy

    @ray.remote(num_cpus=1)
    def where():
        import penumbra as p

        return ray.get_runtime_context().get_node_id(), p.__name__

    pinned = [
        where.options(scheduling_strategy=NodeAffinitySchedulingStrategy(n, soft=False)).remote()
        for n in nodes
    ]
    assert sorted(ray.get(pinned, timeout=120)) == sorted((n, "penumbra") for n in nodes)
    yield c
    ray.shutdown()
    c.shutdown()


@pytest.fixture(scope="module")
def scene():
    return penumbra.load("cornell")


def local_parts(scene, spp, chunks, **kw):
    return [
        (scene.render(spp=spp, spp_range=r, res=RES, **kw), r)
        for r in distributed.chunk_ranges(spp, chunks)
    ]


def test_chunk_ranges_cover_the_samples_once():
    assert distributed.chunk_ranges(10, 4) == [(0, 3), (3, 6), (6, 8), (8, 10)]
    assert distributed.chunk_ranges(5, 5)[-1] == (4, 5)
    with pytest.raises(ValueError, match="chunks"):
        distributed.chunk_ranges(4, 5)


def test_render_is_the_local_merge_bit_for_bit(cluster, scene):
    spp, chunks = 32, 6
    parts = distributed.render_parts("cornell", spp, chunks, res=RES, strategy="mis", seed=3)
    assert [p.range for p in parts] == distributed.chunk_ranges(spp, chunks)
    # Both nodes did work (one CPU each, six tasks).
    assert len({p.node_id for p in parts}) == 2
    img = distributed.render("cornell", spp, chunks, res=RES, strategy="mis", seed=3)
    local = penumbra.merge(local_parts(scene, spp, chunks, strategy="mis", seed=3), spp=spp)
    assert np.array_equal(img, local)
    whole = scene.render(spp=spp, res=RES, strategy="mis", seed=3)
    rel = np.abs(img - whole) / np.maximum(np.abs(whole), 1e-6)
    assert rel.max() < 1e-5


def test_bad_settings_raise_the_renderers_error(cluster):
    with pytest.raises(ValueError, match="expected one of"):
        distributed.render("cornell", 4, 2, res=(8, 8), strategy="nonsense", max_retries=0)
    with pytest.raises(ValueError, match="spp_range"):
        distributed.render("cornell", 4, 2, spp_range=(0, 2))


def test_sweep_table_matches_local_renders(cluster, scene):
    ref = scene.render(spp=64, res=(32, 32))
    grid = {"strategy": ["bsdf", "mis"], "light_selection": ["uniform", "power"], "seed": [0, 1]}
    table = distributed.sweep("cornell", grid, reference=ref, spp=4, res=(32, 32))
    rows = table.to_dict("records") if hasattr(table, "to_dict") else table
    assert len(rows) == 8
    assert [(r["strategy"], r["light_selection"], r["seed"]) for r in rows] == [
        (s, l, seed) for s in grid["strategy"] for l in grid["light_selection"] for seed in grid["seed"]
    ]
    for r in rows:
        img = scene.render(spp=4, res=(32, 32), strategy=r["strategy"],
                           light_selection=r["light_selection"], seed=r["seed"])
        assert r["rel_mse"] == penumbra.compare(img, ref)["rel_mse"]
        assert r["mean"] == float(img.mean())
    # MIS beats BSDF sampling on every row pair: the table says what the lab says.
    by = {(r["strategy"], r["light_selection"], r["seed"]): r["rel_mse"] for r in rows}
    assert all(by[("mis", l, s)] < by[("bsdf", l, s)] for l in grid["light_selection"] for s in (0, 1))


def _chunk_workers():
    """PIDs of worker processes now running a render chunk (Ray titles them ray::TASK)."""
    out = []
    for d in pathlib.Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                cmd = (d / "cmdline").read_bytes()
            except OSError:
                continue
            if cmd.startswith(b"ray::_render_chunk"):
                out.append(int(d.name))
    return out


def test_killed_worker_chunk_is_retried_and_the_image_is_exact(cluster, scene):
    # Chunks of 128 spp at 64x48: long enough (a few tenths of a second) to be caught mid-run.
    spp, chunks = 1024, 8
    killed, done = [], threading.Event()

    def killer():
        while not done.is_set() and not killed:
            pids = _chunk_workers()
            if pids:
                time.sleep(0.05)  # mid-chunk, not at its first instruction
                if pids[0] in _chunk_workers():  # still rendering a chunk
                    os.kill(pids[0], signal.SIGKILL)
                    killed.append(pids[0])
            time.sleep(0.01)

    t = threading.Thread(target=killer)
    t.start()
    try:
        parts = distributed.render_parts("cornell", spp, chunks, res=RES, seed=11, max_retries=2)
    finally:
        done.set()
        t.join()
    assert killed, "no render chunk was seen running: nothing was killed"
    assert not pathlib.Path(f"/proc/{killed[0]}").exists()
    assert [p.range for p in parts] == distributed.chunk_ranges(spp, chunks)
    img = penumbra.merge([(p.image, p.range) for p in parts], spp=spp)
    assert np.array_equal(img, penumbra.merge(local_parts(scene, spp, chunks, seed=11), spp=spp))


def test_without_retries_a_killed_chunk_is_an_error(cluster):
    killed = []

    def killer():
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not killed:
            for pid in _chunk_workers():
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)
                break
            time.sleep(0.02)

    t = threading.Thread(target=killer)
    t.start()
    with pytest.raises(ray.exceptions.RayError):
        distributed.render("cornell", 64, 2, res=RES, max_retries=0)
    t.join()
    assert killed
