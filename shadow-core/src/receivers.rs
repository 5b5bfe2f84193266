//! Receivers handed in by the caller (DESIGN section 3, "Receivers"): a renderer's G-buffer
//! ([`GBuffer`], with its camera when it has one) or bare points with normals (lightmap texels,
//! a path tracer's hit points, vertices), made into the [`ViewSamples`] every technique takes.
//!
//! Foreign positions are snapped onto the scene: a short segment along the receiver's normal,
//! `tolerance` long each way, finds the triangle the point lies on and the exact surface point
//! on it (moved onto the triangle as the built-in rasterizer's hits are), so ray offsets and
//! own-triangle rules keep their guarantees whatever precision the caller's buffer had. A
//! receiver that matches no surface within the tolerance is moved off its point by the
//! tolerance along its normal, marked [`FREE_RECEIVER`], and counted
//! ([`ViewSamples::unmatched_receivers`]).
//!
//! Every input is checked first; a bad one is a [`ReceiverError`] that names the receiver.
//!
//! ```
//! use glam::Vec3;
//! use shadow_core::prelude::*;
//! use shadow_core::receivers::Snapping;
//!
//! // A floor; two lightmap texels, one a hair above it, one nowhere near a surface.
//! let mut builder = SceneBuilder::new();
//! builder.push_mesh(MeshDesc::new(
//!     vec![Vec3::new(-1., 0., -1.), Vec3::new(1., 0., -1.), Vec3::new(1., 0., 1.), Vec3::new(-1., 0., 1.)],
//!     vec![[0, 2, 1], [0, 3, 2]],
//! ))?;
//! let scene = builder.build()?;
//! let texels = [Vec3::new(0.2, 1e-5, 0.3), Vec3::new(0.2, 0.5, 0.3)];
//! let receivers = ViewSamples::from_points(&scene, &texels, &[Vec3::Y; 2], Snapping { tolerance: 1e-3 })?;
//! assert_eq!(receivers.get(0).unwrap().position, Vec3::new(0.2, 0.0, 0.3)); // on the floor
//! assert_eq!(receivers.unmatched_receivers(), 1); // the second, offset by the tolerance
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use glam::{DVec3, UVec3, Vec3};
use rayon::prelude::*;
use thiserror::Error;

use crate::raster::{NO_TRIANGLE, RasterView};
use crate::scene::Scene;
use crate::view_samples::{
    FREE_RECEIVER, MAX_VIEW_PIXELS, ViewSamples, on_surface, surface_normals,
};

/// A renderer's G-buffer, row-major, `width * height` entries in every slice.
#[derive(Debug, Clone, Copy)]
pub struct GBuffer<'a> {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// World position per pixel.
    pub positions: &'a [Vec3],
    /// Geometric normal per pixel, on the side the receiver takes light from (unit length not
    /// required).
    pub geometric_normals: &'a [Vec3],
    /// Shading normal per pixel (the geometric normal's side); interpolated from the scene's
    /// vertex normals when absent.
    pub shading_normals: Option<&'a [Vec3]>,
    /// Diffuse albedo per pixel, for direct light; the scene's when absent.
    pub albedo: Option<&'a [Vec3]>,
    /// Which pixels hold a surface; every pixel when absent.
    pub valid: Option<&'a [bool]>,
    /// The renderer's camera, when it has one: techniques that work in the camera's image (DCS's
    /// shadow volumes, GBP07's screen-space selection) need it. A sub-pixel jitter belongs in its
    /// projection's extents.
    pub camera: Option<RasterView>,
}

/// How foreign receivers are matched to the scene's surfaces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Snapping {
    /// The largest distance, along the receiver's normal, between a receiver and the surface it
    /// lies on (world units): a float G-buffer's rounding, a lightmap texel's offset.
    pub tolerance: f32,
}

impl Snapping {
    /// A tolerance of `1e-4` times the scene's bounding diagonal, floored at `1e-6`: above a
    /// float G-buffer's rounding on any scene the rasterizer keeps accurate.
    pub fn for_scene(scene: &dyn Scene) -> Self {
        Self {
            tolerance: (1e-4 * scene.bounds().diagonal()).max(1e-6),
        }
    }
}

/// Why receivers could not be made.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ReceiverError {
    /// No receiver at all (no point, or a G-buffer without a valid pixel).
    #[error("no receivers: {0}")]
    Empty(&'static str),
    /// A slice's length differs from the receiver count.
    #[error("{what} holds {got} entries for {expected} receivers")]
    Length {
        /// Which slice.
        what: &'static str,
        /// The receiver count.
        expected: usize,
        /// Its length.
        got: usize,
    },
    /// A receiver's value is NaN or infinite.
    #[error("receiver {receiver}: its {what} is not finite")]
    NonFinite {
        /// The receiver's index.
        receiver: usize,
        /// Which value.
        what: &'static str,
    },
    /// A receiver's normal has no direction.
    #[error("receiver {receiver}: its {what} is zero")]
    ZeroNormal {
        /// The receiver's index.
        receiver: usize,
        /// Which normal.
        what: &'static str,
    },
    /// The snapping tolerance is not a positive finite number.
    #[error("snapping tolerance {0} is not a positive finite number")]
    Tolerance(f32),
    /// More receivers than a view may hold.
    #[error("{count} receivers are above the limit of {limit}")]
    TooMany {
        /// Receivers asked for.
        count: u64,
        /// [`MAX_VIEW_PIXELS`].
        limit: u64,
    },
    /// The camera's image is not the G-buffer's size.
    #[error("the camera's image is {camera_width}x{camera_height}, the G-buffer {width}x{height}")]
    CameraSize {
        /// G-buffer width.
        width: u32,
        /// G-buffer height.
        height: u32,
        /// Camera width.
        camera_width: u32,
        /// Camera height.
        camera_height: u32,
    },
}

impl ViewSamples {
    /// Receivers from a renderer's G-buffer, snapped onto `scene` ([`crate::receivers`]).
    ///
    /// # Errors
    /// [`ReceiverError`] naming the first bad receiver or slice.
    pub fn from_gbuffer(
        scene: &dyn Scene,
        g: &GBuffer,
        snapping: Snapping,
    ) -> Result<Self, ReceiverError> {
        let n = u64::from(g.width) * u64::from(g.height);
        if n > MAX_VIEW_PIXELS {
            return Err(ReceiverError::TooMany {
                count: n,
                limit: MAX_VIEW_PIXELS,
            });
        }
        if let Some(c) = &g.camera
            && (c.width, c.height) != (g.width, g.height)
        {
            return Err(ReceiverError::CameraSize {
                width: g.width,
                height: g.height,
                camera_width: c.width,
                camera_height: c.height,
            });
        }
        let input = Input {
            positions: g.positions,
            normals: g.geometric_normals,
            shading: g.shading_normals,
            albedo: g.albedo,
            valid: g.valid,
        };
        input.check(n as usize)?;
        let eye = g
            .camera
            .map(|c| c.view_from_world.inverse().transform_point3(Vec3::ZERO));
        let mut view = snap_all(scene, &input, snapping)?;
        view.width = g.width;
        view.height = g.height;
        view.view = g.camera;
        view.camera_position = eye.unwrap_or(Vec3::ZERO);
        if let Some(c) = &g.camera {
            for (i, d) in view.depth.iter_mut().enumerate() {
                if view.triangle[i] != NO_TRIANGLE {
                    *d = c.depth_of(view.position[i]);
                }
            }
        }
        Ok(view)
    }

    /// Receivers at `positions` facing `normals` (lightmap texels, hit points, vertices), in
    /// the caller's order, with no camera: one row of `positions.len()` receivers, snapped onto
    /// `scene` ([`crate::receivers`]).
    ///
    /// # Errors
    /// [`ReceiverError`] naming the first bad receiver or slice.
    pub fn from_points(
        scene: &dyn Scene,
        positions: &[Vec3],
        normals: &[Vec3],
        snapping: Snapping,
    ) -> Result<Self, ReceiverError> {
        let n = positions.len();
        if n as u64 > MAX_VIEW_PIXELS {
            return Err(ReceiverError::TooMany {
                count: n as u64,
                limit: MAX_VIEW_PIXELS,
            });
        }
        let input = Input {
            positions,
            normals,
            shading: None,
            albedo: None,
            valid: None,
        };
        input.check(n)?;
        let mut view = snap_all(scene, &input, snapping)?;
        view.width = n as u32;
        view.height = 1;
        Ok(view)
    }
}

/// The caller's slices, checked together.
struct Input<'a> {
    positions: &'a [Vec3],
    normals: &'a [Vec3],
    shading: Option<&'a [Vec3]>,
    albedo: Option<&'a [Vec3]>,
    valid: Option<&'a [bool]>,
}

impl Input<'_> {
    fn is_valid(&self, i: usize) -> bool {
        self.valid.is_none_or(|v| v[i])
    }

    /// Lengths first, then every valid receiver's values, in order.
    fn check(&self, n: usize) -> Result<(), ReceiverError> {
        let length = |what, got: usize| {
            (got != n).then_some(ReceiverError::Length {
                what,
                expected: n,
                got,
            })
        };
        let lengths = [
            length("positions", self.positions.len()),
            length("geometric normals", self.normals.len()),
            self.shading
                .and_then(|s| length("shading normals", s.len())),
            self.albedo.and_then(|s| length("albedo", s.len())),
            self.valid.and_then(|s| length("validity mask", s.len())),
        ];
        if let Some(e) = lengths.into_iter().flatten().next() {
            return Err(e);
        }
        if (0..n).all(|i| !self.is_valid(i)) {
            return Err(ReceiverError::Empty("no valid receiver"));
        }
        for i in (0..n).filter(|&i| self.is_valid(i)) {
            let finite = |what, v: Vec3| {
                if v.is_finite() {
                    Ok(())
                } else {
                    Err(ReceiverError::NonFinite { receiver: i, what })
                }
            };
            let direction = |what, v: Vec3| {
                finite(what, v)?;
                if v.length_squared() > 0.0 {
                    Ok(())
                } else {
                    Err(ReceiverError::ZeroNormal { receiver: i, what })
                }
            };
            finite("position", self.positions[i])?;
            direction("geometric normal", self.normals[i])?;
            if let Some(s) = self.shading {
                direction("shading normal", s[i])?;
            }
            if let Some(a) = self.albedo {
                finite("albedo", a[i])?;
            }
        }
        Ok(())
    }
}

/// Every receiver of `input` snapped onto `scene` (size and camera set by the caller).
fn snap_all(
    scene: &dyn Scene,
    input: &Input,
    snapping: Snapping,
) -> Result<ViewSamples, ReceiverError> {
    let t = snapping.tolerance;
    if !(t > 0.0 && t.is_finite()) {
        return Err(ReceiverError::Tolerance(t));
    }
    let grid = SurfaceGrid::new(scene);
    let n = input.positions.len();
    let snapped: Vec<Option<Snapped>> = (0..n)
        .into_par_iter()
        .map(|i| {
            input.is_valid(i).then(|| {
                let normal = input.normals[i].normalize();
                grid.snap(scene, input.positions[i], normal, t)
            })
        })
        .collect();
    let mut view = ViewSamples {
        width: n as u32,
        height: 1,
        camera_position: Vec3::ZERO,
        view: None,
        position: vec![Vec3::ZERO; n],
        geometric_normal: vec![Vec3::ZERO; n],
        shading_normal: vec![Vec3::ZERO; n],
        triangle: vec![NO_TRIANGLE; n],
        depth: vec![f32::INFINITY; n],
        albedo: input.albedo.map(<[Vec3]>::to_vec),
        unmatched: 0,
        sample_pixels: None,
    };
    for (i, s) in snapped.into_iter().enumerate() {
        let Some(s) = s else { continue };
        view.position[i] = s.position;
        view.geometric_normal[i] = s.geometric_normal;
        view.shading_normal[i] = match input.shading {
            Some(sn) => {
                let sn = sn[i].normalize();
                if sn.dot(s.geometric_normal) < 0.0 {
                    -sn
                } else {
                    sn
                }
            }
            None => s.shading_normal,
        };
        view.triangle[i] = s.triangle;
        view.depth[i] = 0.0;
        view.unmatched += u64::from(s.triangle == FREE_RECEIVER);
    }
    Ok(view)
}

/// A receiver placed on the scene.
struct Snapped {
    position: Vec3,
    geometric_normal: Vec3,
    shading_normal: Vec3,
    triangle: u32,
}

/// The scene's triangles binned in a uniform grid of their bounding boxes: a receiver's short
/// segment visits the few cells it crosses.
struct SurfaceGrid {
    min: Vec3,
    cell: Vec3,
    dims: UVec3,
    /// Cell `c`'s triangles are `items[starts[c]..starts[c + 1]]`.
    starts: Vec<u32>,
    items: Vec<u32>,
}

/// Most cells a grid has (each holds a start index).
const MAX_CELLS: u64 = 1 << 22;

impl SurfaceGrid {
    fn new(scene: &dyn Scene) -> Self {
        let b = scene.bounds();
        let extent = (b.max - b.min).max(Vec3::splat(1e-6 * b.diagonal().max(1e-30)));
        let count = scene.triangle_count().max(1) as f64;
        // About two triangles a cell, cells as cubic as the bounds allow.
        let volume = f64::from(extent.x) * f64::from(extent.y) * f64::from(extent.z);
        let side = (volume / (2.0 * count).min(MAX_CELLS as f64)).cbrt();
        let dims = (extent.as_dvec3() / side)
            .ceil()
            .clamp(DVec3::ONE, DVec3::splat(256.0))
            .as_uvec3();
        let cell = extent / dims.as_vec3();
        let mut grid = Self {
            min: b.min,
            cell,
            dims,
            starts: Vec::new(),
            items: Vec::new(),
        };
        let cells = (dims.x * dims.y * dims.z) as usize;
        let ranges: Vec<(UVec3, UVec3)> = (0..scene.triangle_count())
            .map(|t| {
                let [p, q, r] = scene.triangle(t);
                (grid.cell_of(p.min(q).min(r)), grid.cell_of(p.max(q).max(r)))
            })
            .collect();
        let mut counts = vec![0u32; cells + 1];
        for (lo, hi) in &ranges {
            grid.for_cells(*lo, *hi, |c| counts[c + 1] += 1);
        }
        for c in 0..cells {
            counts[c + 1] += counts[c];
        }
        let mut next = counts.clone();
        let mut items = vec![0u32; counts[cells] as usize];
        for (t, (lo, hi)) in ranges.iter().enumerate() {
            grid.for_cells(*lo, *hi, |c| {
                items[next[c] as usize] = t as u32;
                next[c] += 1;
            });
        }
        grid.starts = counts;
        grid.items = items;
        grid
    }

    fn cell_of(&self, p: Vec3) -> UVec3 {
        ((p - self.min) / self.cell)
            .floor()
            .clamp(Vec3::ZERO, (self.dims - 1).as_vec3())
            .as_uvec3()
    }

    fn for_cells(&self, lo: UVec3, hi: UVec3, mut f: impl FnMut(usize)) {
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    f(((z * self.dims.y + y) * self.dims.x + x) as usize);
                }
            }
        }
    }

    /// The surface point nearest `p` along the line through it with unit direction `n`,
    /// within `t` each way, on any triangle (either side); else `p` moved `t` along `n`.
    fn snap(&self, scene: &dyn Scene, p: Vec3, n: Vec3, t: f32) -> Snapped {
        let (a, b) = (p - n * t, p + n * t);
        let (lo, hi) = (self.cell_of(a.min(b)), self.cell_of(a.max(b)));
        let (p64, n64, t64) = (p.as_dvec3(), n.as_dvec3(), f64::from(t));
        let mut best: Option<(f64, usize, DVec3)> = None;
        self.for_cells(lo, hi, |c| {
            for &tri in &self.items[self.starts[c] as usize..self.starts[c + 1] as usize] {
                let tri = tri as usize;
                if let Some((s, hit)) = line_hit(scene.triangle(tri), p64, n64, t64)
                    && best.is_none_or(|(bs, bt, _)| s.abs() < bs.abs() || (s == bs && tri < bt))
                {
                    best = Some((s, tri, hit));
                }
            }
        });
        let Some((_, tri, hit)) = best else {
            return Snapped {
                position: p + n * t,
                geometric_normal: n,
                shading_normal: n,
                triangle: FREE_RECEIVER,
            };
        };
        let corners = scene.triangle(tri).map(|v| v.as_dvec3());
        let [a, b, c] = corners;
        let plane = (b - a).cross(c - a);
        let hit = on_surface(a, b, c, plane, hit);
        // The caller's normal names the side the receiver takes light from.
        let flip = plane.dot(n64) < 0.0;
        let (geo, shading) =
            surface_normals(scene, scene.shading_normals(), tri, corners, hit, flip);
        Snapped {
            position: hit.as_vec3(),
            geometric_normal: geo.as_vec3(),
            shading_normal: shading.as_vec3(),
            triangle: tri as u32,
        }
    }
}

/// Where the line `p + s n` (`|s| <= t`) crosses triangle `tri` (either side, edges
/// included): `s` and the point, in f64.
fn line_hit(tri: [Vec3; 3], p: DVec3, n: DVec3, t: f64) -> Option<(f64, DVec3)> {
    let [a, b, c] = tri.map(|v| v.as_dvec3());
    let plane = (b - a).cross(c - a);
    let denom = plane.dot(n);
    if denom == 0.0 {
        return None;
    }
    let s = plane.dot(a - p) / denom;
    if !(s.abs() <= t) {
        return None;
    }
    let hit = p + n * s;
    // Inside when the three edge functions agree in sign with the plane's normal (a hair of
    // slack for points exactly on an edge).
    let slack = -1e-12 * plane.length_squared();
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|&(u, v)| (v - u).cross(hit - u).dot(plane) >= slack);
    inside.then_some((s, hit))
}
