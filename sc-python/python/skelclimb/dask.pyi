from typing import Any

from . import Mesh, _Mode, _Path, _Triple

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
