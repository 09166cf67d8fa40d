"""Issue 20's measurements of the Python package (run with the wheel installed):

    python python/bench/measure.py [--cli target/release/penumbra] [--runs 3] [--res 128]

1. `import penumbra` time (fresh interpreters, median);
2. Python vs CLI render time of the default scene (cornell, its own resolution and spp):
   `Scene.render()` wall time vs the `render` phase the CLI reports, interleaved runs, medians;
3. a 4096-spp Cornell box (at --res x --res) in 8 chunks on a two-node local Ray cluster
   (head + worker on loopback, 1 CPU each) vs one process with 2 threads: time and the max
   difference (bit-identical to the local merge of the same parts is also checked).
"""

import argparse
import os
import re
import statistics
import subprocess
import sys
import time

import numpy as np


def import_time(runs):
    out = []
    for _ in range(runs):
        r = subprocess.run(
            [sys.executable, "-c", "import time; t=time.perf_counter(); import penumbra; print(time.perf_counter()-t)"],
            capture_output=True, text=True, check=True,
        )
        out.append(float(r.stdout))
    return statistics.median(out)


def py_vs_cli(cli, runs):
    import penumbra

    scene = penumbra.load("cornell")
    py, cl = [], []
    for _ in range(runs):
        t0 = time.perf_counter()
        scene.render()
        py.append(time.perf_counter() - t0)
        r = subprocess.run([cli, "render", "cornell", "-o", "/tmp/measure-cli.exr"], capture_output=True, text=True, check=True)
        m = re.search(r"render ([0-9.]+) ?(ms|s)\b", r.stdout + r.stderr)
        if not m:
            raise SystemExit(f"no render time in the CLI's summary: {r.stdout}{r.stderr}")
        cl.append(float(m.group(1)) / (1000 if m.group(2) == "ms" else 1))
    return statistics.median(py), statistics.median(cl), py, cl


def ray_vs_local(res, spp=4096, chunks=8):
    os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"  # loopback only
    import ray
    from ray.cluster_utils import Cluster

    import penumbra
    from penumbra import distributed

    scene = penumbra.load("cornell")
    t0 = time.perf_counter()
    single = scene.render(spp=spp, res=(res, res), threads=2)
    t_single = time.perf_counter() - t0

    loop = dict(node_ip_address="127.0.0.1", num_cpus=1, object_store_memory=80 * 2**20)
    c = Cluster(initialize_head=True, head_node_args=dict(loop, include_dashboard=False))
    c.add_node(**loop)
    c.wait_for_nodes()
    ray.init(address=c.address, log_to_driver=False)
    try:
        distributed.render("cornell", 2, 2, res=(8, 8))  # warm a worker on each node
        t0 = time.perf_counter()
        parts = distributed.render_parts("cornell", spp, chunks, res=(res, res))
        merged = penumbra.merge([(p.image, p.range) for p in parts], spp=spp)
        t_ray = time.perf_counter() - t0
    finally:
        ray.shutdown()
        c.shutdown()
    local = penumbra.merge(
        [(scene.render(spp=spp, res=(res, res), spp_range=p.range), p.range) for p in parts], spp=spp
    )
    diff = np.abs(merged - single)
    rel = diff / np.maximum(np.abs(single), 1e-6)
    return dict(
        single_s=t_single, ray_s=t_ray, max_abs=float(diff.max()), max_rel=float(rel.max()),
        bit_identical_to_local_merge=bool(np.array_equal(merged, local)),
        nodes=len({p.node_id for p in parts}), chunk_s=[round(p.seconds, 2) for p in parts],
    )


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", default="target/release/penumbra")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--res", type=int, default=128)
    ap.add_argument("--skip", default="")
    a = ap.parse_args()
    if "import" not in a.skip:
        print(f"import penumbra: {import_time(5) * 1000:.0f} ms (median of 5)", flush=True)
    if "render" not in a.skip:
        p, c, ps, cs = py_vs_cli(a.cli, a.runs)
        print(f"default scene: Python {p:.3f} s, CLI render phase {c:.3f} s, overhead {100 * (p / c - 1):+.1f} % "
              f"(medians of {a.runs}; python {[round(x, 3) for x in ps]}, cli {[round(x, 3) for x in cs]})", flush=True)
    if "ray" not in a.skip:
        r = ray_vs_local(a.res)
        print(f"4096 spp cornell {a.res}x{a.res}, 8 chunks: ray 2 nodes x 1 CPU {r['ray_s']:.2f} s vs one process "
              f"2 threads {r['single_s']:.2f} s; max |diff| {r['max_abs']:.3g}, max rel {r['max_rel']:.3g}; "
              f"bit-identical to local merge: {r['bit_identical_to_local_merge']}; nodes used {r['nodes']}; "
              f"chunk times {r['chunk_s']}", flush=True)


if __name__ == "__main__":
    main()
