from typing import Any

from . import Mesh, _Mode, _Triple

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
    compute: bool = ...,
) -> Mesh | Any: ...
