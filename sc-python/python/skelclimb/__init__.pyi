from os import PathLike
from typing import Any, Iterable, Iterator, List, Literal, Mapping, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_Mode = Literal["embedded", "paper", "steps123"]
_Triple = Sequence[float]
_Path = Union[str, PathLike]
_Space = Optional[Literal["RAS", "LPS"]]

class Mesh:
    vertices: npt.NDArray[np.float32]
    faces: npt.NDArray[np.uint32]
    normals: Optional[npt.NDArray[np.float32]]
    stats: dict[str, Any]
    def __init__(
        self,
        vertices: npt.NDArray[np.float32],
        faces: npt.NDArray[np.uint32],
        normals: Optional[npt.NDArray[np.float32]] = ...,
        stats: Optional[dict[str, Any]] = ...,
    ) -> None: ...
    def save(self, path: _Path, *, ascii: bool = ...) -> None: ...
    def to_trimesh(self) -> Any: ...
    def to_pyvista(self) -> Any: ...

def extract(
    volume: npt.NDArray[Any],
    level: float,
    *,
    affine: Optional[npt.ArrayLike] = ...,
    space: _Space = ...,
    spacing: Optional[_Triple] = ...,
    origin: Optional[_Triple] = ...,
    mode: _Mode = ...,
    pad: bool = ...,
    normals: bool = ...,
    threads: int = ...,
    max_error: Optional[float] = ...,
    error_units: Literal["world", "voxels"] = ...,
    max_box: Optional[int] = ...,
    allow_wrong_side: bool = ...,
) -> Mesh: ...
def marching_cubes(
    volume: npt.NDArray[Any],
    level: Optional[float] = ...,
    *,
    spacing: _Triple = ...,
    gradient_direction: Literal["descent", "ascent"] = ...,
    step_size: int = ...,
    allow_degenerate: bool = ...,
    method: Literal["lewiner", "lorensen"] = ...,
    mask: Optional[npt.NDArray[Any]] = ...,
    threads: int = ...,
) -> Tuple[
    npt.NDArray[np.float32],
    npt.NDArray[np.int32],
    npt.NDArray[np.float32],
    npt.NDArray[np.float32],
]: ...
class Atlas:
    vertices: npt.NDArray[np.float32]
    faces: npt.NDArray[np.uint32]
    face_labels: npt.NDArray[np.integer[Any]]
    def __init__(
        self,
        vertices: npt.NDArray[np.float32],
        faces: npt.NDArray[np.uint32],
        face_labels: npt.NDArray[np.integer[Any]],
    ) -> None: ...

class Labels(Mapping[int, Mesh]):
    """Every label's mesh is cut from the atlas the first time any is asked for (indexing,
    ``items()``, ``values()``, ``to_pyvista()``): all at once, with the GIL released, then
    kept. ``labels()``, ``len``, ``in``, the keys, ``atlas`` and ``stats`` cut nothing."""

    atlas: Atlas
    stats: dict[str, Any]
    def __getitem__(self, label: int) -> Mesh: ...
    def __contains__(self, label: object) -> bool: ...
    def __iter__(self) -> Iterator[int]: ...
    def __len__(self) -> int: ...
    def labels(self) -> List[int]: ...
    def to_pyvista(self) -> Any: ...

def labels(
    volume: npt.NDArray[np.integer[Any]],
    *,
    affine: Optional[npt.ArrayLike] = ...,
    space: _Space = ...,
    spacing: Optional[_Triple] = ...,
    origin: Optional[_Triple] = ...,
    labels: Optional[Iterable[int]] = ...,
    background: int = ...,
    mode: _Mode = ...,
    pad: bool = ...,
    normals: bool = ...,
    threads: int = ...,
    smoothing: float = ...,
) -> Labels: ...

class Scan(NamedTuple):
    volume: npt.NDArray[Any]
    affine: npt.NDArray[np.float64]
    space: _Space
    @property
    def spacing(self) -> Tuple[float, float, float]: ...
    @property
    def origin(self) -> Tuple[float, float, float]: ...

def load(
    path: _Path,
    *,
    dims: Optional[Sequence[int]] = ...,
    dtype: Optional[str] = ...,
    endian: Literal["little", "big"] = ...,
    header_bytes: int = ...,
    array: Optional[str] = ...,
    series: Optional[str] = ...,
    resample_gaps: bool = ...,
    zarr_level: int = ...,
) -> Scan: ...

class SliceStreamer:
    def __init__(
        self,
        shape: Sequence[int],
        level: float,
        *,
        spacing: _Triple = ...,
        origin: _Triple = ...,
        mode: _Mode = ...,
        normals: bool = ...,
    ) -> None: ...
    def push(self, slice: npt.NDArray[Any]) -> None: ...
    def finish(self) -> Mesh: ...

class BlockMesh:
    mode: _Mode
    level: float
    normals: bool
    @property
    def triangles(self) -> int: ...
    def merge(self, *others: BlockMesh) -> BlockMesh: ...
    def to_mesh(self) -> Mesh: ...

def block_samples(
    grid: Sequence[int], cubes: Sequence[Tuple[int, int]]
) -> Tuple[Tuple[int, int], Tuple[int, int], Tuple[int, int]]: ...
def extract_block(
    samples: npt.NDArray[Any],
    level: float,
    *,
    at: Sequence[int],
    grid: Sequence[int],
    cubes: Sequence[Tuple[int, int]],
    spacing: _Triple = ...,
    origin: _Triple = ...,
    mode: _Mode = ...,
    normals: bool = ...,
    max_error: Optional[float] = ...,
    error_units: Literal["world", "voxels"] = ...,
) -> BlockMesh: ...

def merge_shards(manifest: _Path) -> Mesh | Labels: ...
def release_memory() -> int: ...
