"""Type stubs of penumbra's compiled module (re-exported by `penumbra`)."""

from typing import List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

class SceneError(ValueError):
    """A scene file that cannot be loaded; the message names file and line."""

class SceneWarning(UserWarning):
    """A loader repaired or approximated something (the message names file and line)."""

class Scene:
    """A loaded scene, ready to render any number of times (`penumbra.load`)."""

    @property
    def name(self) -> str:
        """The scene as given to `load` (built-in name or file path)."""
    @property
    def resolution(self) -> Tuple[int, int]:
        """The scene's own resolution (width, height), used when `render` gets no `res`."""
    @property
    def spp(self) -> Optional[int]:
        """The scene's own samples per pixel, or None (then `render` uses 64)."""
    @property
    def light_count(self) -> int:
        """Number of lights (every emissive triangle counts as one)."""
    @property
    def warnings(self) -> List[str]:
        """The loader's warnings (also issued as `SceneWarning`s when loading)."""
    @property
    def notes(self) -> List[str]:
        """The loader's notes (e.g. the camera automatic framing chose, as CLI flags)."""
    def render(
        self,
        spp: Optional[int] = None,
        shadow_rays: int = 1,
        strategy: str = "mis",
        mis: str = "power",
        light_selection: Optional[str] = None,
        pattern: str = "stratified",
        integrator: Optional[str] = None,
        max_depth: Optional[int] = None,
        res: Union[None, str, Tuple[int, int]] = None,
        seed: int = 0,
        threads: Optional[int] = None,
        spp_range: Optional[Tuple[int, int]] = None,
        mis_light: str = "solid-angle",
        bsdf_sampling: str = "importance",
        hide_emitters: bool = False,
    ) -> npt.NDArray[np.float32]:
        """Render; float32 (height, width, 3) linear RGB, bit for bit the CLI's image.

        strategy: bsdf | light-area | light-solid-angle | mis; mis: power | balance;
        light_selection: uniform | power | spatial | adaptive | wald | bvh | exhaustive;
        pattern: fixed | random | grid | stratified | lhs | sobol; integrator: direct | path
        (max_depth: bounces of path, default 5);
        mis_light: solid-angle | area; bsdf_sampling: importance | cosine | uniform;
        hide_emitters: emitters seen directly by camera rays are black (Mitsuba's
        hide_emitters), the light they cast is unchanged.
        spp_range=(a, b) renders sample indices [a, b) of spp (see `penumbra.merge`).
        The GIL is released; Ctrl-C raises KeyboardInterrupt; bad values raise ValueError.
        """

def builtin_scenes() -> List[Tuple[str, str]]: ...
def load(
    spec: str,
    light_count: Optional[int] = None,
    rooms: Optional[int] = None,
    triangles: Optional[int] = None,
    obj_ka_emission: bool = False,
    look_from: Optional[Sequence[float]] = None,
    look_at: Optional[Sequence[float]] = None,
    up: Optional[Sequence[float]] = None,
    fov: Optional[float] = None,
) -> Scene: ...
def read_image(path: str) -> npt.NDArray[np.float32]: ...
def write_image(path: str, array: npt.NDArray[np.float32], exposure: float = 0.0) -> None: ...
def compare(
    test: npt.NDArray[np.float32],
    reference: npt.NDArray[np.float32],
    test_name: str,
    reference_name: str,
) -> dict: ...
def merge_arrays(
    parts: List[Tuple[npt.NDArray[np.float32], int, int]], spp: int
) -> npt.NDArray[np.float32]: ...
def merge_files(paths: List[str], out: Optional[str] = None) -> npt.NDArray[np.float32]: ...
def warp_list() -> List[Tuple[str, str, List[Tuple[str, str, str]]]]: ...
def warp_sample(
    name: str, n: int, params: List[str], pattern: Optional[str] = None, seed: Optional[int] = None
) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.float64]]: ...
def warp_pdf(
    name: str, points: npt.NDArray[np.float32], params: List[str]
) -> npt.NDArray[np.float64]: ...
