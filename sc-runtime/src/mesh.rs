use alloc::vec;
use alloc::vec::Vec;

use crate::kernel::sink::Unsettled;
use crate::{Error, Params, Scratch, Sink, Stats};

/// An indexed triangle mesh: one vertex per surviving occupied grid edge, none unreferenced.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions in world units.
    pub positions: Vec<[f32; 3]>,
    /// Unit normals, one per position, or empty when normals were not asked for.
    pub normals: Vec<[f32; 3]>,
    /// One value per position ([`Params::values`](crate::Params::values)), or empty when values
    /// were not asked for.
    pub values: Vec<f32>,
    /// Triangles wound so that `(b - a) × (c - a)` points from filled to empty.
    pub triangles: Vec<[u32; 3]>,
    /// Counts before and after merging.
    pub stats: Stats,
}

impl Mesh {
    /// Reserves room for a surface of about `vertices` Steps 1–3 vertices (a [`Survey`]
    /// estimate), with a margin, so that the buffers are allocated once: untouched reserved pages
    /// cost address space, not memory. The margin, half as much again, covers estimates down to
    /// two thirds of the count, and the survey's are within 0.90–1.01 on the benchmark volumes.
    pub(crate) fn reserve_for(&mut self, vertices: usize, params: &Params) {
        let v = Self::room_for(vertices);
        self.positions.reserve_exact(v);
        if params.normals {
            self.normals.reserve_exact(v);
        }
        if params.values {
            self.values.reserve_exact(v);
        }
        self.triangles.reserve_exact(Self::triangle_room(v));
        huge_pages(&mut self.positions);
        huge_pages(&mut self.normals);
        huge_pages(&mut self.values);
        huge_pages(&mut self.triangles);
    }

    /// The vertices to reserve room for, for a survey's estimate of `vertices`.
    pub(crate) fn room_for(vertices: usize) -> usize {
        vertices + vertices / 2
    }

    /// The triangles to reserve room for, next to room for `vertices` vertices: a closed surface
    /// has about two triangles per vertex before merging, and we reserve two and a half. The
    /// extra half keeps glibc from giving the heap back after every extraction with normals.
    /// Once glibc has unmapped a freed block, it keeps later blocks of that size on the heap
    /// and gives the heap's top back to the kernel when more than twice that size is free
    /// there. At two triangles per vertex the triangles are exactly as large as the positions
    /// and the normals together, so freeing a mesh with normals (and values, which the Python
    /// package's `marching_cubes` asks for) would leave just over twice the triangles free, and
    /// the next extraction would fault its pages in again. Untouched room costs address space,
    /// not memory.
    pub(crate) fn triangle_room(vertices: usize) -> usize {
        2 * vertices + vertices / 2
    }
}

/// [`Sink::vertex`], [`Sink::vertex_value`] and [`Sink::triangle`] for a type with
/// `positions`, `normals`, `values` and `triangles` fields that each have a `push`: the mesh's
/// vectors, and a parallel chunk's stretches of them.
/// `push_to_columns!(values and triangles)` leaves [`Sink::vertex`] out, for a type that keeps
/// its normals unsettled (see [`Unsettled`]).
macro_rules! push_to_columns {
    () => {
        #[inline]
        fn vertex(&mut self, position: [f32; 3], normal: Option<[f32; 3]>) {
            self.positions.push(position);
            if let Some(n) = normal {
                self.normals.push(n);
            }
        }

        push_to_columns!(values and triangles);
    };
    (values and triangles) => {
        #[inline]
        fn vertex_value(&mut self, value: f32) {
            self.values.push(value);
        }

        #[inline]
        fn triangle(&mut self, triangle: [u32; 3]) {
            self.triangles.push(triangle);
        }

        #[inline]
        fn cube_triangle_if(&mut self, _: [usize; 3], triangle: [u32; 3], keep: bool) {
            use $crate::mesh::PushIf;
            self.triangles.push_if(triangle, keep);
        }
    };
}

/// A push that writes the value whenever there is room and counts it only if kept: no branch on
/// `keep` (see [`Sink::cube_triangle_if`]).
pub(crate) trait PushIf<T> {
    fn push_if(&mut self, value: T, keep: bool);
}

impl<T> PushIf<T> for Vec<T> {
    #[inline(always)]
    fn push_if(&mut self, value: T, keep: bool) {
        match self.spare_capacity_mut().first_mut() {
            Some(slot) => {
                slot.write(value);
                // SAFETY: the slot past the length was just written, within the capacity.
                unsafe { self.set_len(self.len() + usize::from(keep)) };
            }
            None if keep => self.push(value),
            None => {}
        }
    }
}
#[cfg(feature = "std")]
pub(crate) use push_to_columns;

impl Sink for Mesh {
    push_to_columns!();

    fn expect(&mut self, vertices: usize, triangles: usize) {
        grow(&mut self.positions, vertices);
        if !self.normals.is_empty() {
            grow(&mut self.normals, vertices);
        }
        if !self.values.is_empty() {
            grow(&mut self.values, vertices);
        }
        grow(&mut self.triangles, triangles);
    }
}

/// Room for `more` items past `v`'s length, for a [`Sink::expect`] hint: reserved with a quarter
/// to spare, and only when the hint outgrows the capacity, so the buffers are reallocated a few
/// times at most and never doubled past need. A hint is extrapolated from a volume's header: one
/// the allocator refuses is dropped (the pushes grow the buffers as they need), rather than
/// aborting the process.
pub(crate) fn grow<T>(v: &mut Vec<T>, more: usize) {
    if v.capacity() - v.len() < more {
        let _ = v.try_reserve_exact(more.saturating_add(more / 4));
    }
}

/// A mesh the survey has sized ([`Mesh::reserve_for`]): it takes the sweep's output but not its
/// growth hints. The hints extrapolate the layers done over the layers left; on a surface dense
/// in its first layers (the ITK MRI) they asked for up to 1.6 times the survey's reservation,
/// though the whole surface fitted in it, and each extraction copied its vectors into fresh
/// pages. Should the survey fall short, the vectors still grow as vectors do. It scales normals
/// a layer at a time ([`Sink::settle_normals`]).
pub(crate) struct Presized<'m> {
    mesh: &'m mut Mesh,
    unsettled: Unsettled,
}

impl<'m> Presized<'m> {
    pub fn new(mesh: &'m mut Mesh) -> Self {
        let unsettled = Unsettled::from(mesh.normals.len());
        Presized { mesh, unsettled }
    }
}

impl Sink for Presized<'_> {
    #[inline]
    fn vertex(&mut self, position: [f32; 3], normal: Option<[f32; 3]>) {
        self.mesh.positions.push(position);
        if let Some(n) = normal {
            self.unsettled.push_unit(&mut self.mesh.normals, n);
        }
    }

    #[inline]
    fn edge_vertex_toward(
        &mut self,
        _: [usize; 3],
        _: usize,
        position: [f32; 3],
        toward: [f32; 3],
    ) {
        self.mesh.vertex(position, Some(toward));
    }

    fn settle_normals(&mut self) {
        self.unsettled.settle(&mut self.mesh.normals);
    }

    #[inline]
    fn vertex_value(&mut self, value: f32) {
        self.mesh.vertex_value(value);
    }

    #[inline]
    fn triangle(&mut self, triangle: [u32; 3]) {
        self.mesh.triangle(triangle);
    }

    #[inline]
    fn cube_triangle_if(&mut self, cube: [usize; 3], triangle: [u32; 3], keep: bool) {
        self.mesh.cube_triangle_if(cube, triangle, keep);
    }
}

/// Scratch buffers owned on the heap.
#[derive(Default)]
pub(crate) struct OwnedScratch {
    bytes: Vec<u8>,
    words: Vec<u32>,
}

impl OwnedScratch {
    pub fn new(dims: [usize; 3]) -> Result<Self, Error> {
        let len = Scratch::len(dims)?;
        Ok(OwnedScratch {
            bytes: vec![0; len.bytes],
            words: vec![0; len.words],
        })
    }

    /// Sizes the buffers for `dims`, keeping their memory: fresh buffers are allocated zeroed,
    /// which leaves pages the sweep never touches untouched.
    pub fn fit(&mut self, dims: [usize; 3]) -> Result<(), Error> {
        let len = Scratch::len(dims)?;
        if self.bytes.capacity() < len.bytes || self.words.capacity() < len.words {
            *self = OwnedScratch::new(dims)?;
        } else {
            self.bytes.resize(len.bytes, 0);
            self.words.resize(len.words, 0);
        }
        Ok(())
    }

    /// Bytes held.
    #[cfg(feature = "std")]
    pub fn bytes(&self) -> usize {
        self.bytes.capacity() + core::mem::size_of::<u32>() * self.words.capacity()
    }

    pub fn lend(&mut self) -> Scratch<'_> {
        Scratch {
            bytes: &mut self.bytes,
            words: &mut self.words,
        }
    }
}

/// Buffers this large or larger are worth advice to the kernel about their pages.
#[cfg(all(feature = "std", target_os = "linux"))]
const ADVISE_FROM: usize = 4 << 20;

/// Asks the kernel to back a large buffer with 2 MiB pages, before it is first touched.
#[cfg(all(feature = "std", target_os = "linux"))]
pub(crate) fn huge_pages<T>(v: &mut Vec<T>) {
    if v.capacity() * core::mem::size_of::<T>() >= ADVISE_FROM {
        // SAFETY: MADV_HUGEPAGE changes how pages are backed, never their contents.
        unsafe { advise(v, 0, 2 << 20, libc::MADV_HUGEPAGE) };
    }
}

/// Gives the pages of a buffer's spare room back to the kernel when what was `written` past its
/// length is large. `extract_par`'s chunks write into stretches spread over that room, and after
/// the stretches have moved down the pages they touched stay resident (0.4–0.5 times the
/// triangles' size) for as long as the mesh lives. Below 4 MiB of them the pages are kept: the
/// next extraction writes there again, and given back they would be faulted in again every
/// time.
#[cfg(all(feature = "std", target_os = "linux"))]
pub(crate) fn release_spare<T>(v: &mut Vec<T>, written: usize) {
    if written.saturating_sub(v.len()) * core::mem::size_of::<T>() >= ADVISE_FROM {
        // SAFETY: sysconf has no preconditions.
        let page = usize::try_from(unsafe { libc::sysconf(libc::_SC_PAGESIZE) }).unwrap_or(4096);
        // SAFETY: nothing lives past the vector's length, and Rust treats that room as
        // uninitialised, so its pages reading as zeros afterwards (MADV_DONTNEED) is invisible.
        unsafe { advise(v, v.len(), page, libc::MADV_DONTNEED) };
    }
}

/// `madvise` over the `unit`-aligned part of `v`'s allocation from element `from` on.
///
/// # Safety
/// `advice` is harmless to that part's contents.
#[cfg(all(feature = "std", target_os = "linux"))]
unsafe fn advise<T>(v: &mut Vec<T>, from: usize, unit: usize, advice: libc::c_int) {
    let size = core::mem::size_of::<T>();
    let start = v.as_mut_ptr() as usize;
    let lo = (start + from * size).next_multiple_of(unit);
    let hi = (start + v.capacity() * size) / unit * unit;
    if hi > lo {
        // SAFETY: the range lies within the vector's own allocation, and the caller vouches for
        // the advice.
        unsafe { libc::madvise(lo as *mut libc::c_void, hi - lo, advice) };
    }
}

#[cfg(not(all(feature = "std", target_os = "linux")))]
pub(crate) fn huge_pages<T>(_: &mut Vec<T>) {}

#[cfg(all(feature = "std", not(target_os = "linux")))]
pub(crate) fn release_spare<T>(_: &mut Vec<T>, _: usize) {}

#[cfg(test)]
mod tests {
    use crate::drivers::InMemory;
    use crate::drivers::survey::Survey;
    use crate::kernel::Binary;
    use crate::{Params, Volume, extract};
    use alloc::vec::Vec;

    /// A ball in the first quarter of the layers: after its first layers the sweep's hints
    /// extrapolate its surface over all 95 layers, many times what there is. The survey's
    /// reservation holds the whole surface, and no hint reallocates it. The triangles' share of
    /// it keeps a freed mesh with normals under glibc's trim threshold.
    #[test]
    fn a_surveyed_mesh_keeps_its_reservation() {
        let dims = [32, 32, 96];
        let data: Vec<f32> = (0..dims.iter().product::<usize>())
            .map(|i| {
                let d = |c: usize, at: f32| c as f32 - at;
                let (x, y, z) = (d(i % 32, 15.5), d((i / 32) % 32, 15.5), d(i / 1024, 14.0));
                12.0 - (x * x + y * y + z * z).sqrt()
            })
            .collect();
        let src = InMemory {
            data: &data,
            nxy: 32 * 32,
        };
        let estimate =
            Survey::new(&src, dims, &Binary::<f32>::new(&Params::new(0.0))).between(0, dims[2]);
        let reserved = estimate + estimate / 2;
        let mesh = extract(&Volume::new(&data, dims).unwrap(), &Params::new(0.0)).unwrap();
        assert!(
            mesh.positions.len() <= reserved && mesh.triangles.len() <= 2 * reserved,
            "{estimate} {} {}",
            mesh.positions.len(),
            mesh.triangles.len()
        );
        assert_eq!(mesh.positions.capacity(), reserved);
        assert_eq!(mesh.triangles.capacity(), 2 * reserved + reserved / 2);
        // With normals and values (`f32`, a third of a position: the `p / 3` below), as the
        // Python package's `marching_cubes` asks for them, everything freed stays under twice
        // the triangle vector, glibc's threshold for giving the heap back (see
        // `Mesh::triangle_room`).
        let params = Params {
            normals: true,
            values: true,
            ..Params::new(0.0)
        };
        let mesh = extract(&Volume::new(&data, dims).unwrap(), &params).unwrap();
        assert_eq!(mesh.values.capacity(), mesh.positions.capacity());
        let bytes = |n: usize| 12 * n;
        let (p, n, t) = (
            bytes(mesh.positions.capacity()),
            bytes(mesh.normals.capacity()),
            bytes(mesh.triangles.capacity()),
        );
        assert!(p + n + t + p / 3 < 2 * t, "{p} + {n} + {t}");
    }

    /// A vector with 8 MiB of spare room, all of it written: after `release_spare` its elements
    /// are intact and the spare room's whole pages are no longer resident (`mincore`).
    #[cfg(all(feature = "std", target_os = "linux"))]
    #[test]
    fn released_spare_room_leaves_the_elements_and_drops_the_pages() {
        let len = 1 << 20;
        let mut v: Vec<u32> = Vec::with_capacity(3 * len);
        v.extend((0..3 * len as u32).map(|i| i.wrapping_mul(2_654_435_761)));
        v.truncate(len);
        super::release_spare(&mut v, 3 * len);
        assert!(
            v.iter()
                .enumerate()
                .all(|(i, &x)| x == (i as u32).wrapping_mul(2_654_435_761))
        );
        let page = 4096;
        let start = (v.as_ptr() as usize + 4 * len).next_multiple_of(page);
        let end = (v.as_ptr() as usize + 4 * v.capacity()) / page * page;
        let mut resident = std::vec![0u8; (end - start) / page];
        // SAFETY: the range lies within the vector's allocation, and `resident` has a byte per
        // page of it.
        let ok = unsafe {
            libc::mincore(
                start as *mut libc::c_void,
                end - start,
                resident.as_mut_ptr(),
            )
        };
        assert_eq!(ok, 0);
        assert!(resident.iter().all(|&r| r & 1 == 0));
    }
}
