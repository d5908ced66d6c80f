"""Type stubs of the streamrt module (docs/python.md)."""
from typing import Any, Callable, Optional, TypedDict

import numpy as np
import numpy.typing as npt

class SceneError(ValueError):
    """A mistake in a scene: where it is and what is wrong."""
    file: str
    line: int
    column: int
    message: str

class Scene:
    """A scene built from Python: .cfg statements and meshes from NumPy arrays."""
    def __init__(self) -> None: ...
    def add(self, text: str) -> None:
        """Appends statements (one or more lines of .cfg text)."""
    def statement(self, word: str, **keys: Any) -> None:
        """Appends one statement: statement('sphere', color=(1, 0, 0), translate=(0, 1, 0))."""
    def mesh(self, vertices: npt.ArrayLike, triangles: npt.ArrayLike, *, colors: Optional[npt.ArrayLike] = None,
             **keys: Any) -> None:
        """Appends a mesh object: vertices (n, 3), triangles (m, 3), and the mesh statement's keys."""
    def csg(self, op: str, **keys: Any) -> CsgBlock:
        """A csg block: `with scene.csg('difference', rotate_x=90):` writes `csg difference
        rotate_x=90`, the statements added in the body as its children, then `end`."""
    @property
    def text(self) -> str:
        """The statements as .cfg text (meshes named file=memory:K)."""

class CsgBlock:
    """A csg block being written (Scene.csg), used in a with statement."""
    def __enter__(self) -> Scene: ...
    def __exit__(self, *exc: Any) -> bool: ...

class Result:
    """One render."""
    @property
    def image(self) -> npt.NDArray[np.float32]:
        """height x width x 3, linear, top row first: the numbers of the CLI's PFM."""
    @property
    def seconds(self) -> dict[str, float]:
        """'read', 'setup', 'render'."""
    @property
    def rays(self) -> dict[str, int]:
        """'primary', 'shadow', 'reflected', 'refracted', 'total'."""
    @property
    def profile(self) -> Optional[dict[str, Any]]:
        """The content of --profile=json (stream engine, profile=True), else None."""
    @property
    def engine(self) -> str:
        """'stream' or 'recursive'."""
    @property
    def adaptive(self) -> Optional[dict[str, Any]]:
        """Adaptive sampling: 'mean_spp', 'estimated_rmse', 'rounds', 'time_limited', 'cap' (the
        most samples a pixel took) and 'cap_from' ('spp', 'scene' or 'default'), 'above_at_cap'
        (pixels the cap stopped above their threshold), 'cut_short_by' (None when the request
        was met, else 'cap', 'time_limit' or 'threshold'), 'seconds' and 'sample_map' (height x
        width x 3: samples taken, estimated standard error, 0); else None."""

def render(
    scene: str | Scene,
    *,
    width: Optional[int] = ...,
    height: Optional[int] = ...,
    spp: Optional[int] = ...,
    depth: Optional[int] = ...,
    degree: Optional[int] = ...,
    sampler: Optional[str] = ...,
    cutoff: Optional[float] = ...,
    light_samples: Optional[int] = ...,
    engine: Optional[str] = ...,
    isa: Optional[str] = ...,
    accel: Optional[str] = ...,
    threads: Optional[int] = ...,
    frame: Optional[int] = ...,
    colorspace: Optional[str] = ...,
    tonemap: Optional[str] = ...,
    exposure: Optional[float] = ...,
    adaptive: Optional[float] = ...,
    target_error: Optional[float] = ...,
    time_limit: Optional[float] = ...,
    profile: bool = ...,
    progress: Optional[Callable[[int, int], None]] = ...,
    memory_limit: Optional[int | str] = ...,
) -> Result:
    """Renders a scene (a .cfg path or its text) with the command line's overrides.

    memory_limit: the most memory the process may hold during the call (bytes, or '4G'),
    as --memory-limit; MemoryError when reading or rendering would need more."""

def compare(scene: str | Scene, **overrides: Any) -> dict[str, Any]:
    """Both engines: 'stream' and 'recursive' Results, 'speedup', 'rmse', 'psnr', 'max_abs', 'share_over'."""

def save(
    image: npt.ArrayLike, path: str, colorspace: str = ..., tonemap: str = ..., exposure: float = ...
) -> None:
    """Writes a linear height x width x 3 image in the format of the path's extension."""
