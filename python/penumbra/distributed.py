"""Renders and sweeps on a Ray cluster.

The unit of work is a *sample range*: chunk ``[a, b)`` renders sample indices a..b-1 of every
pixel (``Scene.render(spp_range=(a, b))``), a pure function of the scene, the settings and
the range, whichever node runs it and with however many threads. So a chunk that fails or
whose worker is killed is simply run again (Ray's ``max_retries``), and the merged image is
bit for bit what merging the same parts rendered locally gives.

>>> from penumbra import distributed
>>> img = distributed.render("cornell", spp=4096, chunks=8, address="auto")
>>> table = distributed.sweep("cornell", {"strategy": ["bsdf", "mis"], "seed": [0, 1]},
...                           spp=16, res=(128, 128))

Ray is an optional dependency (``pip install "penumbra[distributed]"``). The scene path must
name the same scene on every node (a built-in name, or a file on a shared filesystem), and
every node needs this package installed (or a ``runtime_env`` that installs it).
"""

from __future__ import annotations

import itertools
import os
import time
from dataclasses import dataclass
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple

import numpy as np

__all__ = ["Part", "chunk_ranges", "render", "render_parts", "sweep"]

#: Ray's default for task retries is 3; a render chunk is cheap to redo and idempotent.
DEFAULT_RETRIES = 3


@dataclass(frozen=True)
class Part:
    """One rendered chunk: its sample range, the image of those samples, where it ran."""

    range: Tuple[int, int]
    image: np.ndarray
    node_id: str
    pid: int
    seconds: float


def chunk_ranges(spp: int, chunks: int) -> List[Tuple[int, int]]:
    """Split samples ``0..spp`` into ``chunks`` contiguous ranges whose sizes differ by at most
    one (the first ``spp % chunks`` get the extra sample)."""
    spp, chunks = int(spp), int(chunks)
    if spp < 1:
        raise ValueError(f"spp must be at least 1, got {spp}")
    if not 1 <= chunks <= spp:
        raise ValueError(f"chunks must be in 1..={spp} (one sample at least each), got {chunks}")
    q, r = divmod(spp, chunks)
    out, a = [], 0
    for i in range(chunks):
        b = a + q + (1 if i < r else 0)
        out.append((a, b))
        a = b
    return out


def _ray():
    try:
        import ray
    except ImportError:
        raise ImportError(
            "penumbra.distributed needs Ray: pip install 'penumbra[distributed]' (or ray)"
        ) from None
    return ray


def _connect(address: Optional[str], init_kw: Optional[Mapping[str, Any]]):
    """Attach to ``address`` (None: the running session, else RAY_ADDRESS, else a local one)."""
    ray = _ray()
    if not ray.is_initialized():
        kw = dict(init_kw or {})
        kw.setdefault("log_to_driver", False)
        ray.init(address=address, **kw)
    return ray


# The scenes a worker process has loaded, so the chunks it runs do not each parse the scene
# again (a worker process runs many tasks). Keyed by path and load knobs.
_SCENES: Dict[Tuple[str, Tuple], Any] = {}


def _scene(scene_path: str, knobs: Mapping[str, Any]):
    import penumbra

    key = (scene_path, tuple(sorted((k, repr(v)) for k, v in knobs.items())))
    if key not in _SCENES:
        _SCENES[key] = penumbra.load(scene_path, **knobs)
    return _SCENES[key]


def _worker_id() -> str:
    try:
        import ray

        return ray.get_runtime_context().get_node_id()
    except Exception:  # outside Ray (a local call of the task body)
        return "local"


def _render_chunk(scene_path, knobs, settings, spp, rng, threads):
    """Task body: one sample range of the render; also says where and how long it ran."""
    t0 = time.perf_counter()
    img = _scene(scene_path, knobs).render(spp=spp, spp_range=tuple(rng), threads=threads, **settings)
    return img, _worker_id(), os.getpid(), time.perf_counter() - t0


def _sweep_task(scene_path, knobs, settings, reference, threads):
    """Task body: one point of a sweep; its image, metrics against the reference, time."""
    import penumbra

    scene = _scene(scene_path, knobs)
    t0 = time.perf_counter()
    img = scene.render(threads=threads, **settings)
    seconds = time.perf_counter() - t0
    row = dict(seconds=seconds, mean=float(img.mean()))
    if reference is not None:
        row.update(penumbra.compare(img, reference))
    return row, img, _worker_id()


def _remote(ray, fn, cpus, retries):
    # retry_exceptions stays False: a Python error (bad argument, bad scene) would fail again;
    # max_retries covers what retrying fixes, a worker process or node that died.
    # SPREAD: chunks go round the nodes rather than piling onto the first one with a free
    # CPU, so a render uses the whole cluster even when chunks are short.
    return ray.remote(num_cpus=cpus, max_retries=retries, scheduling_strategy="SPREAD")(fn)


def render_parts(
    scene_path: str,
    spp: int,
    chunks: int,
    *,
    address: Optional[str] = None,
    max_retries: int = DEFAULT_RETRIES,
    cpus_per_task: int = 1,
    load_knobs: Optional[Mapping[str, Any]] = None,
    ray_init: Optional[Mapping[str, Any]] = None,
    **settings: Any,
) -> List[Part]:
    """Render ``chunks`` sample ranges of ``spp`` as Ray tasks; the parts in sample order.

    ``settings`` are `Scene.render`'s keywords (``res``, ``strategy``, ``seed``, ...; not
    ``spp_range`` or ``threads``: each task renders with ``cpus_per_task`` threads, which
    does not change the image). ``max_retries``: how often a chunk whose worker died is run
    again. ``address``: the cluster (``"auto"``, ``"ray://host:10001"``, ``"host:6379"``);
    None attaches to the running Ray session, else starts a local one.
    """
    for bad in ("spp_range", "threads", "spp"):
        if bad in settings:
            raise ValueError(f"{bad}= is chosen by distributed.render_parts, not a setting")
    ranges = chunk_ranges(spp, chunks)
    scene_path = os.fspath(scene_path)
    knobs = dict(load_knobs or {})
    ray = _connect(address, ray_init)
    task = _remote(ray, _render_chunk, cpus_per_task, max_retries)
    refs = [task.remote(scene_path, knobs, settings, int(spp), r, cpus_per_task) for r in ranges]
    out = []
    for r, ref in zip(ranges, refs):
        img, node, pid, secs = ray.get(ref)
        out.append(Part(r, img, node, pid, secs))
    return out


def render(scene_path: str, spp: int, chunks: int, **kw: Any) -> np.ndarray:
    """Render ``scene_path`` with ``spp`` samples per pixel in ``chunks`` Ray tasks and merge
    them (`penumbra.merge`: weights by sample count, summed in sample order), so the result
    is bit-identical to merging the same parts rendered in one process, and equal to the
    whole render up to float rounding. Keywords as `render_parts`."""
    import penumbra

    parts = render_parts(scene_path, spp, chunks, **kw)
    return penumbra.merge([(p.image, p.range) for p in parts], spp=int(spp))


def _grid_points(grid: Mapping[str, Sequence[Any]]) -> List[Dict[str, Any]]:
    if not grid:
        raise ValueError("grid: expected a mapping of setting -> list of values")
    keys = list(grid)
    values = []
    for k in keys:
        v = grid[k]
        if isinstance(v, (str, bytes)) or not isinstance(v, Iterable):
            v = [v]
        v = list(v)
        if not v:
            raise ValueError(f"grid[{k!r}] is empty")
        values.append(v)
    return [dict(zip(keys, combo)) for combo in itertools.product(*values)]


def sweep(
    scene_path: str,
    grid: Mapping[str, Sequence[Any]],
    *,
    reference: Any = None,
    address: Optional[str] = None,
    max_retries: int = DEFAULT_RETRIES,
    cpus_per_task: int = 1,
    load_knobs: Optional[Mapping[str, Any]] = None,
    ray_init: Optional[Mapping[str, Any]] = None,
    keep_images: bool = False,
    **settings: Any,
):
    """Render every point of ``grid`` (e.g. ``{"strategy": [...], "light_selection": [...],
    "seed": [...]}``: the Cartesian product of `Scene.render` keyword values) as one Ray task
    each, with ``settings`` fixed for all, and return one row per point in grid order: the
    point's settings, ``seconds`` (render time on its worker), ``mean`` (image mean), ``node``
    and, when ``reference`` (an array or image file) is given, ``mse``, ``rel_mse`` and
    ``mae`` against it (`penumbra.compare`). A `pandas.DataFrame` if pandas is installed,
    else a list of dicts; ``keep_images=True`` adds an ``image`` column."""
    import penumbra

    points = _grid_points(grid)
    clash = sorted(set(grid) & set(settings))
    if clash:
        raise ValueError(f"{', '.join(clash)} given both in grid and as fixed settings")
    if "threads" in grid or "threads" in settings:
        raise ValueError("threads= is cpus_per_task in a sweep")
    scene_path = os.fspath(scene_path)
    knobs = dict(load_knobs or {})
    if isinstance(reference, (str, os.PathLike)):
        reference = penumbra.read_image(reference)
    ray = _connect(address, ray_init)
    task = _remote(ray, _sweep_task, cpus_per_task, max_retries)
    ref_obj = None if reference is None else ray.put(np.asarray(reference, dtype=np.float32))
    refs = [
        task.remote(scene_path, knobs, dict(settings, **p), ref_obj, cpus_per_task) for p in points
    ]
    rows = []
    for p, ref in zip(points, refs):
        metrics, img, node = ray.get(ref)
        row = dict(p, **metrics, node=node)
        if keep_images:
            row["image"] = img
        rows.append(row)
    try:
        import pandas as pd
    except ImportError:
        return rows
    return pd.DataFrame(rows)
