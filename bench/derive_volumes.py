#!/usr/bin/env python3
"""Benchmark volumes beyond the shared set: larger, and in the sample types users bring.

The shared volumes are small (the MRIs have 0.3-8.7 M samples) and only u8 and i16. From them
this script derives, into OUT (a folder in the layout SC_DATA_DIR expects:
<name>/<name>.raw + <name>.json):

- stent-ct-2x      i16, 256 x 256 x 256: the stent CT upsampled 2x in x and y (linear, rounded
                   to integers), at a bone level and a skin level (air is 0 in this CT);
- brainsmall-2x    u8, 256 x 256 x 168: the brainsmall MRI upsampled 2x on every axis, at the
                   integer iso 20 where many samples tie with the iso value;
- mni152-f32       f32, 197 x 233 x 189: the MNI template smoothed by a 3-tap box on each axis
                   (so values are no longer integers), at the brain and white-matter levels.

    SC_DATA_DIR=../shared/data python3 bench/derive_volumes.py target/bench-data
    SC_DATA_DIR=target/bench-data cargo bench -p sc-runtime --bench extract

Needs only NumPy. bench/compare.py calls it itself when SC_DATA_DIR is set.
"""
import json, os, sys
import numpy as np


def load(data_dir, name):
    with open(os.path.join(data_dir, name, name + ".json")) as f:
        meta = json.load(f)
    dtype = {"u8": np.uint8, "i16": np.int16, "u16": np.uint16}[meta["dtype"]]
    nx, ny, nz = meta["dims"]
    raw = np.fromfile(os.path.join(data_dir, name, name + ".raw"), dtype=np.dtype(dtype).newbyteorder("<"))
    return raw.reshape(nz, ny, nx), meta


def upsample(a, axes):
    """Linear 2x upsampling along `axes` (array axes of a z, y, x array): n samples become
    2n - 1, the new ones halfway between neighbours."""
    out = a.astype(np.float64)
    for ax in axes:
        n = out.shape[ax]
        shape = list(out.shape)
        shape[ax] = 2 * n - 1
        up = np.empty(shape)
        even = [slice(None)] * out.ndim
        even[ax] = slice(0, None, 2)
        odd = [slice(None)] * out.ndim
        odd[ax] = slice(1, None, 2)
        lo = [slice(None)] * out.ndim
        lo[ax] = slice(0, n - 1)
        hi = [slice(None)] * out.ndim
        hi[ax] = slice(1, n)
        up[tuple(even)] = out
        up[tuple(odd)] = 0.5 * (out[tuple(lo)] + out[tuple(hi)])
        out = up
    return out


def pad_to(a, shape):
    """Pads with the edge values to `shape` (z, y, x), so dims come out round."""
    return np.pad(a, [(0, s - n) for s, n in zip(shape, a.shape)], mode="edge")


def smooth(a):
    out = a.astype(np.float64)
    for ax in range(3):
        p = np.pad(out, [(1, 1) if d == ax else (0, 0) for d in range(3)], mode="edge")
        lo = [slice(None)] * 3
        mid = [slice(None)] * 3
        hi = [slice(None)] * 3
        lo[ax], mid[ax], hi[ax] = slice(0, -2), slice(1, -1), slice(2, None)
        out = (p[tuple(lo)] + p[tuple(mid)] + p[tuple(hi)]) / 3.0
    return out


def save(out_dir, name, a, dtype, source, isos):
    os.makedirs(os.path.join(out_dir, name), exist_ok=True)
    a = np.ascontiguousarray(a.astype(np.dtype(dtype).newbyteorder("<")))
    nz, ny, nx = a.shape
    a.tofile(os.path.join(out_dir, name, name + ".raw"))
    meta = {
        "dims": [nx, ny, nz],
        "dtype": {np.uint8: "u8", np.int16: "i16", np.float32: "f32"}[dtype],
        "spacing": [1.0, 1.0, 1.0],
        "order": "x fastest",
        "source": source,
        "iso_suggestions": isos,
    }
    with open(os.path.join(out_dir, name, name + ".json"), "w") as f:
        json.dump(meta, f, indent=1)
    print(f"{name}: {nx} x {ny} x {nz} {meta['dtype']}, iso {isos}")


def main():
    data_dir = os.environ.get("SC_DATA_DIR")
    if not data_dir or len(sys.argv) != 2:
        sys.exit(__doc__)
    out_dir = sys.argv[1]
    stent, _ = load(data_dir, "stent-ct")
    up = np.rint(upsample(stent, axes=(1, 2)))
    save(out_dir, "stent-ct-2x", pad_to(up, (256, 256, 256)), np.int16,
         "stent-ct upsampled 2x in x and y (bench/derive_volumes.py)",
         {"bone": 400, "skin": 30})
    brain, _ = load(data_dir, "brainsmall-mri")
    up = np.rint(upsample(brain, axes=(0, 1, 2)))
    save(out_dir, "brainsmall-2x", pad_to(up, (168, 256, 256)), np.uint8,
         "brainsmall-mri upsampled 2x (bench/derive_volumes.py)", {"skin": 20})
    mni, _ = load(data_dir, "mni152-mri")
    save(out_dir, "mni152-f32", smooth(mni), np.float32,
         "mni152-mri smoothed by a 3-tap box per axis, as f32 (bench/derive_volumes.py)",
         {"brain": 80, "white_matter": 190})


if __name__ == "__main__":
    main()
