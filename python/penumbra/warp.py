"""The sampling routines of `penumbra warp` (the lab's warp registry), for external
chi-square harnesses (``mitsuba.chi2``, SciPy): draw samples with the density each routine
claims, or evaluate that density anywhere.

Directions are unit 3-vectors with densities per unit solid angle; planar routines give
(x, y) points with densities per unit area. ``params`` is a dict ``{key: value}`` (or a list
of ``"KEY=VALUE"`` strings) overriding the routine's defaults; `routines()` lists them.
"""

from __future__ import annotations

from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native

Params = Union[None, Mapping[str, Any], Sequence[str]]


def _params(params: Params) -> List[str]:
    if params is None:
        return []
    if isinstance(params, Mapping):
        out = []
        for k, v in params.items():
            if isinstance(v, (list, tuple, np.ndarray)):
                v = ",".join(str(float(x)) for x in v)
            out.append(f"{k}={v}")
        return out
    if isinstance(params, str):
        return [params]
    return [str(p) for p in params]


def routines() -> Dict[str, dict]:
    """Every routine: ``{name: {"summary": str, "params": {key: (default, help)}}}``."""
    return {
        name: {"summary": summary, "params": {k: (d, h) for k, d, h in params}}
        for name, summary, params in _native.warp_list()
    }


def sample(
    name: str,
    n: int,
    params: Params = None,
    pattern: Optional[str] = None,
    seed: Optional[int] = None,
) -> Tuple[np.ndarray, np.ndarray]:
    """Make ``n`` sampling attempts of routine ``name``; returns ``(samples, pdf)``: the
    accepted samples (float32, m x 3 directions or m x 2 points, m <= n: BSDFs reject samples
    below the horizon) and the routine's density at each (float64, m).

    Without ``pattern`` the 2D inputs come from the test suite's chi-square stream (``seed``
    defaults to the suite's seed: the very samples `cargo test` checks); with a pattern name
    (fixed, random, grid, stratified, lhs, sobol) sample i warps that pattern's point i of n.
    An unknown name, parameter or pattern raises `ValueError` listing the valid ones.
    """
    return _native.warp_sample(str(name), int(n), _params(params), pattern, seed)


def pdf(name: str, directions: Any, params: Params = None) -> np.ndarray:
    """The density routine ``name`` claims at each row of ``directions`` (m x 3 directions,
    normalised first, or m x 2 points); float64, m. Zero or non-finite rows get 0."""
    pts = np.ascontiguousarray(directions, dtype=np.float32)
    if pts.ndim == 1:
        pts = pts[None, :]
    if pts.ndim != 2:
        raise ValueError(f"directions: expected an m x 3 (or m x 2) array, got shape {pts.shape}")
    return _native.warp_pdf(str(name), pts, _params(params))
