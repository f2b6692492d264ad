//! `skelclimb render`: a mesh to a PNG, so a result can be looked at on a machine without a
//! display. An orthographic camera, a z-buffer and headlight Lambert shading (flat, or Gouraud
//! with `--smooth`); triangle edges drawn depth-tested over the surface; two meshes side by side;
//! triangles coloured by their distance to a reference mesh.

mod distance;
mod font;

use std::path::Path;

use sc_io::atomic::AtomicFile;
use sc_io::mesh_in::{self, TriangleMesh};
use sc_io::{Error, Result};

use crate::cli::{RenderArgs, View};

const BACKGROUND: [u8; 3] = [255, 255, 255];
const SURFACE: [f64; 3] = [176.0, 190.0, 214.0];
const EDGE: [u8; 3] = [35, 35, 45];
const TEXT: [u8; 3] = [20, 20, 20];

/// An RGB picture.
pub struct Image {
    width: usize,
    height: usize,
    rgb: Vec<u8>,
}

impl Image {
    fn new(width: usize, height: usize) -> Self {
        Image {
            width,
            height,
            rgb: BACKGROUND.repeat(width * height),
        }
    }

    fn set(&mut self, x: usize, y: usize, c: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = 3 * (x + self.width * y);
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }
}

/// Orthographic view: screen axes `right`, `up`, and `toward` the viewer.
#[derive(Clone, Copy)]
struct Camera {
    right: [f64; 3],
    up: [f64; 3],
    toward: [f64; 3],
}

impl Camera {
    /// z is up; azimuth 0 looks along +y (from −y), 90 along −x; elevation 90 looks down.
    fn new(azimuth: f64, elevation: f64) -> Self {
        let (a, e) = (azimuth.to_radians(), elevation.to_radians());
        let toward = [e.cos() * a.sin(), -e.cos() * a.cos(), e.sin()];
        let right = [a.cos(), a.sin(), 0.0];
        Camera {
            right,
            up: cross(toward, right),
            toward,
        }
    }

    fn project(&self, p: [f32; 3]) -> [f64; 3] {
        let p = p.map(f64::from);
        [dot(p, self.right), dot(p, self.up), dot(p, self.toward)]
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = dot(a, a).sqrt();
    if l > 0.0 { a.map(|c| c / l) } else { a }
}

/// Renders and writes the picture.
pub fn run(args: &RenderArgs, quiet: bool) -> Result<()> {
    if !args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        return Err(Error::Usage(format!(
            "{}: the picture is written as PNG; name it .png",
            args.output.display()
        )));
    }
    let [width, height] = args.size;
    let (azimuth, elevation) = match args.view {
        Some(View::Front) => (0.0, 0.0),
        Some(View::Side) => (90.0, 0.0),
        Some(View::Top) => (0.0, 90.0),
        Some(View::Iso) | None => (args.azimuth.unwrap_or(35.0), args.elevation.unwrap_or(25.0)),
    };
    let camera = Camera::new(azimuth, elevation);
    let (first, labels) = if args.mesh.is_dir() {
        let (mesh, colours) = read_labels(&args.mesh)?;
        (mesh, Some(colours))
    } else {
        (read(&args.mesh)?, None)
    };
    let mut meshes = vec![first];
    if let Some(other) = &args.compare {
        meshes.push(read(other)?);
    }
    let colours = match &args.color_by_error {
        Some(reference) => {
            let d = distance::per_triangle(&meshes[0], &read(reference)?);
            let max = d.iter().copied().fold(0.0, f64::max);
            let mean = d.iter().sum::<f64>() / d.len() as f64;
            if !quiet {
                eprintln!(
                    "distance to {}: max {max:.4}, mean {mean:.4} (mesh units, from triangle centroids)",
                    reference.display()
                );
            }
            Some((d, max))
        }
        None => None,
    };
    let file = AtomicFile::create(&args.output)?;
    let panels = meshes.len();
    let mut image = Image::new(width * panels, height);
    // One framing for all panels: the union of the projected bounds.
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for m in &meshes {
        for &p in &m.positions {
            let q = camera.project(p);
            for d in 0..2 {
                lo[d] = lo[d].min(q[d]);
                hi[d] = hi[d].max(q[d]);
            }
        }
    }
    let label_room = if panels > 1 || colours.is_some() {
        30.0
    } else {
        0.0
    };
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(f64::MIN_POSITIVE);
    let scale = 0.92 * (width as f64).min(height as f64 - label_room) / extent;
    let frame = Frame {
        centre: [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0],
        scale,
        width,
        height,
        label_room,
    };
    for (n, m) in meshes.iter().enumerate() {
        let tint = match (n, &colours, &labels) {
            (0, Some((d, max)), _) => Tint::Error(d, *max),
            (0, None, Some(labels)) => Tint::Labels(labels),
            _ => Tint::Plain,
        };
        draw(&mut image, m, &camera, &frame, n * width, args, tint);
        if panels > 1 {
            let label = format!(
                "{} triangles",
                crate::summary::thousands(m.triangles.len() as u64)
            );
            font::draw(&mut image, &label, n * width + 10, 8, 2, TEXT);
        }
    }
    if let Some((_, max)) = &colours {
        font::draw(
            &mut image,
            &format!("max {max:.3}"),
            10,
            height - 24,
            2,
            TEXT,
        );
    }
    let filled = file.fill(|out| {
        let mut encoder = png::Encoder::new(out, image.width as u32, image.height as u32);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
        writer
            .write_image_data(&image.rgb)
            .map_err(std::io::Error::other)
    })?;
    crate::interrupt::finish(|| filled.commit())
}

fn read(path: &Path) -> Result<TriangleMesh> {
    mesh_in::read(path)
}

/// The meshes of a directory of label meshes as one, with each triangle's colour: the label's
/// default colour, the id read from the file's name (`17-Name.ply`, `label-17.ply`).
fn read_labels(dir: &Path) -> Result<(TriangleMesh, Vec<[f64; 3]>)> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| mesh_in::readable(p))
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(Error::file(
            dir,
            "no .ply, .obj or .stl mesh in the directory",
        ));
    }
    let mut all = TriangleMesh::default();
    let mut colours = Vec::new();
    for path in files {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy())
            .unwrap_or_default();
        let id = stem
            .trim_start_matches("label-")
            .split('-')
            .next()
            .and_then(|n| n.parse::<u64>().ok())
            .unwrap_or(0);
        let mesh = read(&path)?;
        let base = all.positions.len() as u32;
        all.positions.extend_from_slice(&mesh.positions);
        all.triangles
            .extend(mesh.triangles.iter().map(|t| t.map(|v| v + base)));
        let rgb = sc_io::labels::default_rgb(id).map(f64::from);
        colours.resize(all.triangles.len(), rgb);
    }
    Ok((all, colours))
}

/// How a panel's triangles are coloured.
enum Tint<'a> {
    Plain,
    /// By distance to a reference, up to the largest.
    Error(&'a [f64], f64),
    /// Per triangle.
    Labels(&'a [[f64; 3]]),
}

/// Where world units land on the picture.
struct Frame {
    centre: [f64; 2],
    scale: f64,
    width: usize,
    height: usize,
    label_room: f64,
}

impl Frame {
    fn pixel(&self, q: [f64; 3], left: usize) -> [f64; 3] {
        [
            left as f64 + self.width as f64 / 2.0 + (q[0] - self.centre[0]) * self.scale,
            (self.height as f64 + self.label_room) / 2.0 - (q[1] - self.centre[1]) * self.scale,
            q[2],
        ]
    }
}

/// Fills one panel: shaded triangles through a z-buffer, then the depth-tested edges.
fn draw(
    image: &mut Image,
    mesh: &TriangleMesh,
    camera: &Camera,
    frame: &Frame,
    left: usize,
    args: &RenderArgs,
    tint: Tint,
) {
    let (w, h) = (frame.width, frame.height);
    let mut depth = vec![f64::NEG_INFINITY; w * h];
    let screen: Vec<[f64; 3]> = mesh
        .positions
        .iter()
        .map(|&p| frame.pixel(camera.project(p), 0))
        .collect();
    let light = normalize([
        camera.toward[0] + 0.4 * camera.up[0] - 0.3 * camera.right[0],
        camera.toward[1] + 0.4 * camera.up[1] - 0.3 * camera.right[1],
        camera.toward[2] + 0.4 * camera.up[2] - 0.3 * camera.right[2],
    ]);
    let face_normal = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize].map(f64::from));
        cross(
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
        )
    };
    let shade = |n: [f64; 3]| 0.18 + 0.82 * dot(normalize(n), light).abs();
    // Gouraud: per-vertex intensities from area-weighted face normals.
    let vertex_light: Option<Vec<f64>> = args.smooth.then(|| {
        let mut normals = vec![[0.0; 3]; mesh.positions.len()];
        for t in &mesh.triangles {
            let n = face_normal(t);
            for &i in t {
                let v = &mut normals[i as usize];
                *v = [v[0] + n[0], v[1] + n[1], v[2] + n[2]];
            }
        }
        normals.into_iter().map(shade).collect()
    });
    for (n, t) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = t.map(|i| screen[i as usize]);
        let base = match tint {
            Tint::Error(d, max) => ramp(if max > 0.0 { d[n] / max } else { 0.0 }),
            Tint::Labels(colours) => colours[n],
            Tint::Plain => SURFACE,
        };
        let flat = shade(face_normal(t));
        let lights = t.map(|i| vertex_light.as_ref().map_or(flat, |l| l[i as usize]));
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if area.abs() < 1e-12 {
            continue;
        }
        let x0 = a[0].min(b[0]).min(c[0]).floor().max(0.0) as usize;
        let x1 = (a[0].max(b[0]).max(c[0]).ceil() as usize).min(w - 1);
        let y0 = a[1].min(b[1]).min(c[1]).floor().max(0.0) as usize;
        let y1 = (a[1].max(b[1]).max(c[1]).ceil() as usize).min(h - 1);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                let wa = ((b[0] - px) * (c[1] - py) - (b[1] - py) * (c[0] - px)) / area;
                let wb = ((c[0] - px) * (a[1] - py) - (c[1] - py) * (a[0] - px)) / area;
                let wc = 1.0 - wa - wb;
                if wa < 0.0 || wb < 0.0 || wc < 0.0 {
                    continue;
                }
                let z = wa * a[2] + wb * b[2] + wc * c[2];
                if z > depth[x + w * y] {
                    depth[x + w * y] = z;
                    let l = wa * lights[0] + wb * lights[1] + wc * lights[2];
                    image.set(left + x, y, base.map(|c| (c * l).clamp(0.0, 255.0) as u8));
                }
            }
        }
    }
    if args.wireframe {
        // A small depth allowance lets an edge win against the faces it bounds.
        let tolerance = 1e-3 * (mesh_depth_range(&screen) + 1e-9);
        for t in &mesh.triangles {
            for k in 0..3 {
                let (p, q) = (screen[t[k] as usize], screen[t[(k + 1) % 3] as usize]);
                let steps = (q[0] - p[0]).abs().max((q[1] - p[1]).abs()).ceil().max(1.0) as usize;
                for s in 0..=steps {
                    let f = s as f64 / steps as f64;
                    let (x, y, z) = (
                        p[0] + f * (q[0] - p[0]),
                        p[1] + f * (q[1] - p[1]),
                        p[2] + f * (q[2] - p[2]),
                    );
                    if x < 0.0 || y < 0.0 || x >= w as f64 || y >= h as f64 {
                        continue;
                    }
                    let (xi, yi) = (x as usize, y as usize);
                    if z >= depth[xi + w * yi] - tolerance {
                        image.set(left + xi, yi, EDGE);
                    }
                }
            }
        }
    }
}

fn mesh_depth_range(screen: &[[f64; 3]]) -> f64 {
    let (lo, hi) = screen
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p[2]), hi.max(p[2]))
        });
    hi - lo
}

/// Blue (0) through pale yellow to red (1).
fn ramp(t: f64) -> [f64; 3] {
    let t = t.clamp(0.0, 1.0);
    if t < 0.5 {
        let s = t * 2.0;
        [60.0 + 195.0 * s, 110.0 + 135.0 * s, 230.0 - 40.0 * s]
    } else {
        let s = (t - 0.5) * 2.0;
        [255.0, 245.0 - 195.0 * s, 190.0 - 150.0 * s]
    }
}
