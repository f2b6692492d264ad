from typing import Any, Iterable, Optional

import numpy.typing as npt

from . import Labels, Mesh, _Mode, _Path, _Space, _Triple

def extract(
    array: Any,
    level: float,
    *,
    spacing: _Triple = ...,
    origin: _Triple = ...,
    mode: _Mode = ...,
    normals: bool = ...,
    max_error: float | None = ...,
    error_units: str = ...,
    split_every: int = ...,
    shards: _Path | None = ...,
    compute: bool = ...,
) -> Mesh | str | Any: ...
def labels(
    array: Any,
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
    smoothing: float = ...,
    split_every: int = ...,
    shards: _Path | None = ...,
    compute: bool = ...,
) -> Labels | str | Any: ...
