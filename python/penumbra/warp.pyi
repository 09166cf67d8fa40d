"""Type stubs of `penumbra.warp` (docstrings in the implementation)."""

from typing import Any, Dict, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

Params = Union[None, Mapping[str, Any], Sequence[str]]

def routines() -> Dict[str, dict]: ...
def sample(
    name: str,
    n: int,
    params: Params = None,
    pattern: Optional[str] = None,
    seed: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.float64]]: ...
def pdf(name: str, directions: npt.ArrayLike, params: Params = None) -> npt.NDArray[np.float64]: ...
