"""Type stubs of the `penumbra` package (docstrings in the implementation)."""

import os
from typing import Any, Iterable, List, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import warp as warp
from ._native import Scene as Scene
from ._native import SceneError as SceneError
from ._native import SceneWarning as SceneWarning

PathLike = Union[str, "os.PathLike[str]"]
LOAD_KNOBS: Tuple[str, ...]

def builtin_scenes() -> List[Tuple[str, str]]: ...
def load(
    path_or_builtin: PathLike,
    *,
    light_count: Optional[int] = ...,
    rooms: Optional[int] = ...,
    triangles: Optional[int] = ...,
    obj_ka_emission: bool = ...,
    look_from: Optional[Tuple[float, float, float]] = ...,
    look_at: Optional[Tuple[float, float, float]] = ...,
    up: Optional[Tuple[float, float, float]] = ...,
    fov: Optional[float] = ...,
) -> Scene: ...
def read_image(path: PathLike) -> npt.NDArray[np.float32]: ...
def write_image(path: PathLike, array: npt.ArrayLike, exposure: float = 0.0) -> None: ...
def compare(test: Union[PathLike, npt.ArrayLike], ref: Union[PathLike, npt.ArrayLike]) -> dict: ...
def merge(
    parts: Iterable[Any], spp: Optional[int] = None, out: Optional[PathLike] = None
) -> npt.NDArray[np.float32]: ...
