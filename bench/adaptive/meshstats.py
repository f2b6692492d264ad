"""Mesh measures for the adaptive benchmark: shape, topology, distance, and sides of samples.

Every function takes a mesh as `(points, faces)`: float64 `(n, 3)` positions in grid-index
coordinates (x, y, z; sample `v[z, y, x]` sits at `(x, y, z)`) and int `(m, 3)` vertex indices.
"""
import numpy as np
import vtk
from vtk.util import numpy_support


def min_angles(points, faces, spacing):
    """Each triangle's smallest angle in degrees, measured in world space (index × spacing)."""
    p = points * np.asarray(spacing, dtype=np.float64)
    a, b, c = p[faces[:, 0]], p[faces[:, 1]], p[faces[:, 2]]

    def angle(at, u, v):
        d1, d2 = u - at, v - at
        cos = np.einsum("ij,ij->i", d1, d2)
        sin = np.linalg.norm(np.cross(d1, d2), axis=1)
        return np.degrees(np.arctan2(sin, cos))

    return np.minimum(np.minimum(angle(a, b, c), angle(b, c, a)), angle(c, a, b))


def edge_use(faces):
    """How the undirected edges are shared: counts of edges in 1, 2 and 3+ triangles, and the
    directed edges that appear twice (two triangles on one side: misoriented)."""
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    und = np.sort(directed, axis=1)
    _, count = np.unique(und, axis=0, return_counts=True)
    _, dcount = np.unique(directed, axis=0, return_counts=True)
    return {
        "border": int((count == 1).sum()),
        "manifold": int((count == 2).sum()),
        "nonmanifold": int((count >= 3).sum()),
        "misoriented": int((dcount >= 2).sum()),
    }


def lattice_samples(points, faces, step):
    """Points on every triangle: the barycentric lattice with `n = ceil(longest side / step)`
    divisions per side (corners and sides included). Returns the points, the triangle of each,
    and each triangle's covering radius: every point of triangle `t` lies within `radius[t]` of
    one of its samples (`longest side / (n · sqrt 3)`: each point of a small triangle of longest
    side `s` is within `s / sqrt 3` of one of its corners)."""
    a, b, c = points[faces[:, 0]], points[faces[:, 1]], points[faces[:, 2]]
    longest = np.max(
        [np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1), np.linalg.norm(a - c, axis=1)],
        axis=0,
    )
    n = np.maximum(1, np.ceil(longest / step)).astype(np.int64)
    pts, tri = [], []
    for k in np.unique(n):
        sel = np.flatnonzero(n == k)
        i, j = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
        keep = i + j <= k
        u, v = i[keep] / k, j[keep] / k
        w = 1.0 - u - v
        pts.append(
            (w[None, :, None] * a[sel][:, None, :] + u[None, :, None] * b[sel][:, None, :]
             + v[None, :, None] * c[sel][:, None, :]).reshape(-1, 3)
        )
        tri.append(np.repeat(sel, len(u)))
    return np.concatenate(pts), np.concatenate(tri), longest / (n * np.sqrt(3.0))


def polydata(points, faces):
    pts = vtk.vtkPoints()
    pts.SetData(numpy_support.numpy_to_vtk(np.ascontiguousarray(points, dtype=np.float64), deep=True))
    cells = vtk.vtkCellArray()
    offsets = np.arange(0, 3 * len(faces) + 1, 3, dtype=np.int64)
    cells.SetData(
        numpy_support.numpy_to_vtkIdTypeArray(offsets, deep=True),
        numpy_support.numpy_to_vtkIdTypeArray(np.ascontiguousarray(faces, dtype=np.int64).ravel(), deep=True),
    )
    pd = vtk.vtkPolyData()
    pd.SetPoints(pts)
    pd.SetPolys(cells)
    return pd


def from_polydata(pd):
    """`(points, faces)` of a triangle-only vtkPolyData."""
    points = numpy_support.vtk_to_numpy(pd.GetPoints().GetData()).astype(np.float64)
    polys = pd.GetPolys()
    offsets = numpy_support.vtk_to_numpy(polys.GetOffsetsArray())
    if len(offsets) > 1 and not np.all(np.diff(offsets) == 3):
        raise ValueError("mesh has non-triangle cells")
    faces = numpy_support.vtk_to_numpy(polys.GetConnectivityArray()).reshape(-1, 3).astype(np.int64)
    return points, faces


class DistanceTo:
    """Unsigned distance from points to the nearest point of a triangle mesh: VTK's exact
    point–triangle distance through its cell locator, built once."""

    def __init__(self, mesh):
        self.f = vtk.vtkImplicitPolyDataDistance()
        self.f.SetInput(polydata(*mesh))

    def __call__(self, query):
        # Neighbouring triangles' lattices share their corners and sides: each point within
        # 2^-20 grid steps of another is measured once.
        q = np.round(query * 2.0**20).astype(np.int64)
        order = np.lexsort(q.T)
        q = q[order]
        first = np.r_[True, np.any(q[1:] != q[:-1], axis=1)]
        group = np.empty(len(query), dtype=np.int64)
        group[order] = np.cumsum(first) - 1
        rep = np.ascontiguousarray(query[order[first]], dtype=np.float64)
        out = vtk.vtkDoubleArray()
        self.f.FunctionValue(numpy_support.numpy_to_vtk(rep, deep=True), out)
        return np.abs(numpy_support.vtk_to_numpy(out))[group]


def one_way(mesh, to, step, tol, budget):
    """Mean and maximum distance from the points of `mesh` to the mesh `to`. The mean is over
    the lattice samples at `step`. The maximum is bracketed: the largest sampled distance, and
    an upper bound from each triangle's largest sample plus its covering radius (distance is
    1-Lipschitz); triangles whose bound exceeds the largest sample by more than `tol` are
    resampled twice as finely while the samples stay within `budget`."""
    dist = DistanceTo(to)
    points, faces = mesh
    pts, tri, radius = lattice_samples(points, faces, step)
    d = dist(pts)
    mean = float(d.mean())
    upper = np.full(len(faces), -np.inf)
    np.maximum.at(upper, tri, d)
    upper += radius
    lower = float(d.max())
    while True:
        active = np.flatnonzero(upper > lower + tol)
        if len(active) == 0:
            break
        step /= 2
        pts, tri, radius = lattice_samples(points, faces[active], step)
        if len(pts) > budget:
            break
        d = dist(pts)
        sub = np.full(len(active), -np.inf)
        np.maximum.at(sub, tri, d)
        upper[active] = sub + radius
        lower = max(lower, float(d.max()))
    return {"mean": mean, "max": lower, "max_upper": float(max(lower, upper.max()))}


def symmetric_distance(mesh, reference, step, tol=0.02, budget=3_000_000):
    """Distances both ways between `mesh` and `reference` (see `one_way`)."""
    to, back = one_way(mesh, reference, step, tol, budget), one_way(reference, mesh, step, tol, budget)
    return {
        "to_ref": to, "from_ref": back,
        "mean": (to["mean"] + back["mean"]) / 2,
        "max": max(to["max"], back["max"]),
        "max_upper": max(to["max_upper"], back["max_upper"]),
    }


# Rays run along +x through (y, z) = (j + EY, k + EZ): off the lattice by less than any surface
# comes near a sample, and at no simple ratio, so that no ray meets a mesh vertex or side.
EY, EZ = 1.0e-6 * np.sqrt(2.0), 1.0e-6 * np.sqrt(3.0)


def inside_by_parity(points, faces, shape):
    """For every sample of a volume of shape `(nz, ny, nx)`: whether the mesh encloses it, by
    the parity of the mesh's crossings with the ray from the sample towards +x. Returns the
    boolean array and the number of rays crossing the mesh an odd number of times (0 for a
    closed mesh)."""
    nz, ny, nx = shape
    f = faces
    # Each side's orientation test is computed once per undirected edge, from its lower-numbered
    # vertex, so that two triangles sharing a side agree exactly about which side a ray is on.
    def edge_fn(u, v, py, pz):
        lo, hi = np.minimum(u, v), np.maximum(u, v)
        sign = np.where(u < v, 1.0, -1.0)
        ly, lz = points[lo, 1], points[lo, 2]
        hy, hz = points[hi, 1], points[hi, 2]
        return sign * ((hy - ly) * (pz - lz) - (hz - lz) * (py - ly))

    ys, zs = points[f, 1], points[f, 2]
    j0 = np.ceil(ys.min(axis=1) - EY).astype(np.int64)
    j1 = np.floor(ys.max(axis=1) - EY).astype(np.int64)
    k0 = np.ceil(zs.min(axis=1) - EZ).astype(np.int64)
    k1 = np.floor(zs.max(axis=1) - EZ).astype(np.int64)
    nj, nk = np.maximum(0, j1 - j0 + 1), np.maximum(0, k1 - k0 + 1)
    per = nj * nk
    tri = np.repeat(np.arange(len(f)), per)
    local = np.arange(per.sum()) - np.repeat(np.cumsum(per) - per, per)
    j = j0[tri] + local % nj[tri]
    k = k0[tri] + local // nj[tri]
    py, pz = j + EY, k + EZ
    a, b, c = f[tri, 0], f[tri, 1], f[tri, 2]
    w0, w1, w2 = edge_fn(b, c, py, pz), edge_fn(c, a, py, pz), edge_fn(a, b, py, pz)
    hit = ((w0 > 0) & (w1 > 0) & (w2 > 0)) | ((w0 < 0) & (w1 < 0) & (w2 < 0))
    w0, w1, w2 = w0[hit], w1[hit], w2[hit]
    a, b, c, j, k = a[hit], b[hit], c[hit], j[hit], k[hit]
    x = (w0 * points[a, 0] + w1 * points[b, 0] + w2 * points[c, 0]) / (w0 + w1 + w2)
    ok = (j >= 0) & (j < ny) & (k >= 0) & (k < nz)
    width = nx + 4.0
    line = k[ok] * ny + j[ok]
    keys = np.sort(line * width + (x[ok] + 1.0))
    per_line = np.bincount(line, minlength=ny * nz)
    odd = int((per_line % 2 == 1).sum())
    lines = np.arange(ny * nz, dtype=np.float64)
    sample = (lines[:, None] * width + (np.arange(nx)[None, :] + 1.0)).ravel()
    end = np.repeat(lines * width + width, nx)
    beyond = np.searchsorted(keys, end, "left") - np.searchsorted(keys, sample, "right")
    return (beyond % 2 == 1).reshape(nz, ny, nx), odd


class Sides:
    """Which samples of a volume are inside (`value >= iso`), and the band of those within 2
    samples (Chebyshev) of a sample of the other side."""

    def __init__(self, volume, iso):
        from scipy import ndimage

        self.inside = volume >= iso
        out = ~self.inside
        boundary = (self.inside & ~ndimage.binary_erosion(self.inside, border_value=0)) | (
            out & ~ndimage.binary_erosion(out, border_value=1))
        self.band = ndimage.binary_dilation(boundary, structure=np.ones((5, 5, 5), bool))

    def wrong(self, points, faces):
        """Samples whose side by the mesh differs from their own, over all samples and within
        the band, and the rays crossing the mesh an odd number of times."""
        inside_mesh, odd = inside_by_parity(points, faces, self.inside.shape)
        wrong = inside_mesh != self.inside
        return {
            "wrong": int(wrong.sum()),
            "wrong_in_band": int((wrong & self.band).sum()),
            "band_samples": int(self.band.sum()),
            "odd_rays": odd,
        }
