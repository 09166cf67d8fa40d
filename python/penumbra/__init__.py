"""penumbra from Python: load scenes, render them into numpy arrays, compare, merge, warp.

>>> import penumbra
>>> scene = penumbra.load("cornell")
>>> img = scene.render(spp=16, res=(256, 256))     # float32 H x W x 3, linear RGB
>>> penumbra.write_image("cornell.exr", img)

Everything computes in the renderer's Rust library: an array rendered here is bit for bit the
image `penumbra render` writes for the same settings.
"""

from __future__ import annotations

import os
from typing import Any, Iterable, Optional, Tuple, Union

import numpy as np

from . import _native
from . import warp
from ._native import Scene, SceneError, SceneWarning

__all__ = [
    "Scene",
    "SceneError",
    "SceneWarning",
    "builtin_scenes",
    "compare",
    "load",
    "merge",
    "read_image",
    "warp",
    "write_image",
]

PathLike = Union[str, "os.PathLike[str]"]

#: The keyword knobs `load` accepts (the CLI's scene flags).
LOAD_KNOBS = (
    "light_count",
    "rooms",
    "triangles",
    "obj_ka_emission",
    "look_from",
    "look_at",
    "up",
    "fov",
)


def builtin_scenes() -> list:
    """The built-in scenes as (name, description) pairs (what `penumbra scenes` prints)."""
    return list(_native.builtin_scenes())


def load(path_or_builtin: PathLike, **knobs: Any) -> Scene:
    """Load a built-in scene (``"cornell"``, see `builtin_scenes`) or a scene file
    (``.pbrt``, ``.obj``, ``.gltf``/``.glb``).

    Knobs are the CLI's scene flags: ``light_count``, ``rooms``, ``triangles`` (built-in
    scenes), ``obj_ka_emission`` (OBJ), ``look_from``/``look_at``/``up`` (3 numbers) and
    ``fov`` (degrees) to refine the camera.

    The loader's repairs and approximations are issued as `SceneWarning` (a `UserWarning`)
    naming file and line; a missing file raises `FileNotFoundError` naming it, a file that
    cannot be loaded `SceneError` (a `ValueError`) with file:line.
    """
    unknown = sorted(set(knobs) - set(LOAD_KNOBS))
    if unknown:
        raise TypeError(
            f"load() got unknown knob(s) {', '.join(unknown)} "
            f"(valid: {', '.join(LOAD_KNOBS)})"
        )
    for k in ("look_from", "look_at", "up"):
        if knobs.get(k) is not None:
            knobs[k] = _vec3(k, knobs[k])
    return _native.load(os.fspath(path_or_builtin), **knobs)


def _vec3(name: str, v: Any) -> list:
    try:
        out = [float(x) for x in v]
    except TypeError:
        raise ValueError(f"{name}: expected three numbers, got {v!r}") from None
    if len(out) != 3:
        raise ValueError(f"{name}: expected three numbers, got {v!r}")
    return out


def _as_image(a: Any, what: str) -> np.ndarray:
    arr = np.ascontiguousarray(a, dtype=np.float32)
    if arr.ndim != 3 or arr.shape[2] != 3:
        raise ValueError(f"{what}: expected an H x W x 3 array, got shape {arr.shape}")
    return arr


def read_image(path: PathLike) -> np.ndarray:
    """Read an image (EXR, PFM, HDR: linear; PNG, TGA, JPEG: sRGB-decoded) as a float32
    H x W x 3 array of linear RGB. A missing file raises `FileNotFoundError`."""
    return _native.read_image(os.fspath(path))


def write_image(path: PathLike, array: Any, exposure: float = 0.0) -> None:
    """Write a linear H x W x 3 array as EXR or PFM (float) or PNG (sRGB, ``exposure`` in
    stops), chosen by the extension; atomically, as the CLI writes its images."""
    _native.write_image(os.fspath(path), _as_image(array, "array"), float(exposure))


def compare(test: Union[PathLike, Any], ref: Union[PathLike, Any]) -> dict:
    """Error metrics of ``test`` against ``ref`` (arrays or image files), the numbers
    `penumbra compare` prints: ``{"mse": ..., "rel_mse": ..., "mae": ...}`` (relMSE = mean of
    (a - b)^2 / (b^2 + 0.01)). Differing sizes raise `ValueError`; NaN pixels and 8-bit vs
    float comparisons warn."""

    def get(x: Any, what: str) -> Tuple[np.ndarray, str]:
        if isinstance(x, (str, os.PathLike)):
            return read_image(x), os.fspath(x)
        return _as_image(x, what), f"<{what} array>"

    (t, tn), (r, rn) = get(test, "test"), get(ref, "ref")
    return dict(_native.compare(t, r, tn, rn))


def merge(
    parts: Iterable[Any], spp: Optional[int] = None, out: Optional[PathLike] = None
) -> np.ndarray:
    """Combine the sample-range parts of one render into the whole image.

    ``parts`` are either part files (EXR written by ``penumbra render --spp-range``; their
    headers say which samples they hold) or ``(array, (a, b))`` pairs from
    ``Scene.render(spp_range=(a, b))`` with ``spp=`` the whole render's sample count. The
    parts must cover sample indices 0..spp exactly once (a gap or an overlap raises
    `ValueError`); each is weighted by its sample count and they are summed in sample order,
    so the result is the same for any order of ``parts`` and equals the whole render up to
    float rounding. ``out`` (files only) also writes the merged image.
    """
    parts = list(parts)
    if parts and all(isinstance(p, (str, os.PathLike)) for p in parts):
        if spp is not None:
            raise ValueError("spp= is for array parts; part files record their own")
        return _native.merge_files([os.fspath(p) for p in parts], None if out is None else os.fspath(out))
    if out is not None:
        raise ValueError("out= is for part files; write array results with write_image")
    if spp is None:
        raise ValueError("array parts need spp= (the whole render's samples per pixel)")
    native = []
    for p in parts:
        try:
            arr, (a, b) = p
        except (TypeError, ValueError):
            raise ValueError(
                f"expected part files or (array, (a, b)) pairs, got {type(p).__name__}"
            ) from None
        native.append((_as_image(arr, "part"), int(a), int(b)))
    return _native.merge_arrays(native, int(spp))

