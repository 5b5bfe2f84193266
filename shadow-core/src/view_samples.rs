//! View samples (the G-buffer): per pixel the first surface hit through the pixel centre, shared
//! by every technique and the reference so that differences come from shadows alone
//! (DESIGN section 3).
//!
//! The rasterizer decides which triangle a pixel sees; the position is then the exact
//! intersection of the pixel's camera ray with that triangle's plane (computed in f64), so it
//! equals a ray tracer's hit point rather than an interpolated approximation.
//!
//! Receivers may also come from the caller ([`crate::receivers`]): a renderer's G-buffer, with
//! its camera when it has one, or bare points with normals, snapped onto the scene.

use glam::{DVec3, UVec2, Vec3};
use rayon::prelude::*;

use crate::camera::Camera;
use crate::raster::{NO_TRIANGLE, RasterError, RasterView, rasterize};
use crate::scene::Scene;

/// The largest view, in pixels (8192 x 4096): view samples cost about 64 bytes a pixel (2 GiB
/// here), a technique's outputs more (per-sample visibility: `N / 8` bytes a pixel), so a larger
/// request is refused before anything is allocated rather than exhausting memory.
pub const MAX_VIEW_PIXELS: u64 = 1 << 25;
/// Marks a receiver that matched no surface of the scene within the caller's tolerance
/// ([`crate::receivers`]): it lies on no triangle, so no triangle is its own.
pub const FREE_RECEIVER: u32 = NO_TRIANGLE - 1;

/// The receivers whose visibility is wanted: the G-buffer of one camera view, a caller's
/// G-buffer, or a caller's points (one row, no camera).
#[derive(Debug, Clone, PartialEq)]
pub struct ViewSamples {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) camera_position: Vec3,
    pub(crate) view: Option<RasterView>,
    pub(crate) position: Vec<Vec3>,
    pub(crate) geometric_normal: Vec<Vec3>,
    pub(crate) shading_normal: Vec<Vec3>,
    pub(crate) triangle: Vec<u32>,
    pub(crate) depth: Vec<f32>,
    /// The caller's albedo per receiver, when it handed one in.
    pub(crate) albedo: Option<Vec<Vec3>>,
    /// Receivers that matched no surface and were offset by the caller's tolerance.
    pub(crate) unmatched: u64,
    /// The pixel each receiver's light samples are drawn for, where it is not its place in
    /// this layout (receivers reordered by [`crate::spatial_order::SpatialOrder`]).
    pub(crate) sample_pixels: Option<Vec<UVec2>>,
}

/// One valid view sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewSample {
    /// Pixel coordinates: the pixel its light samples are drawn for. Its place in the layout,
    /// except for receivers a technique reordered ([`crate::spatial_order::SpatialOrder`]),
    /// which keep the caller's pixel so that their samples do not change.
    pub pixel: UVec2,
    /// World position on the surface.
    pub position: Vec3,
    /// Unit geometric normal, flipped to face the camera.
    pub geometric_normal: Vec3,
    /// Unit shading normal (interpolated, on the camera's side like the geometric normal).
    pub shading_normal: Vec3,
    /// Triangle id ([`FREE_RECEIVER`] for a caller's point that matched no surface).
    pub triangle: u32,
    /// Linear depth along the camera axis (0 without a camera).
    pub depth: f32,
    /// The caller's albedo, when it handed one in.
    pub albedo: Option<Vec3>,
}

impl ViewSample {
    /// The diffuse albedo shading uses: the caller's, else the scene's at the receiver's
    /// triangle, else white for a receiver on no triangle.
    pub fn albedo_in(&self, scene: &dyn Scene) -> Vec3 {
        match self.albedo {
            Some(a) => a,
            None if (self.triangle as usize) < scene.triangle_count() => {
                scene.albedo_at(self.triangle as usize, self.position)
            }
            None => Vec3::ONE,
        }
    }
}

impl ViewSamples {
    /// Renders the view samples of `scene` seen by `camera` at `width x height`.
    ///
    /// # Errors
    /// [`RasterError`] for a zero or too large image.
    pub fn render(
        scene: &dyn Scene,
        camera: &Camera,
        width: u32,
        height: u32,
    ) -> Result<Self, RasterError> {
        let view = camera.raster_view(width, height);
        let mut samples = Self::render_view(scene, &view)?;
        if let Some(far) = camera.far() {
            samples.clip_beyond(far);
        }
        Ok(samples)
    }

    /// Makes every pixel whose surface lies deeper than `far` background: the nearest surface
    /// of a pixel is its nearest within the far plane or none, so clipping the nearest is
    /// clipping every fragment.
    fn clip_beyond(&mut self, far: f32) {
        for i in 0..self.triangle.len() {
            if self.triangle[i] != NO_TRIANGLE && self.depth[i] > far {
                self.triangle[i] = NO_TRIANGLE;
                self.position[i] = Vec3::ZERO;
                self.geometric_normal[i] = Vec3::ZERO;
                self.shading_normal[i] = Vec3::ZERO;
                self.depth[i] = f32::INFINITY;
            }
        }
    }

    /// Renders the view samples for any raster view (perspective or orthographic).
    ///
    /// # Errors
    /// [`RasterError`] for an invalid view.
    pub fn render_view(scene: &dyn Scene, view: &RasterView) -> Result<Self, RasterError> {
        let pixels = u64::from(view.width) * u64::from(view.height);
        if pixels > MAX_VIEW_PIXELS {
            return Err(RasterError::TooManyPixels {
                width: view.width,
                height: view.height,
                limit: MAX_VIEW_PIXELS,
            });
        }
        let frags = rasterize(scene.positions(), scene.triangles(), view, 1)?;
        let (w, h) = (view.width, view.height);
        let world_from_view = view.view_from_world.inverse();
        let camera_position = world_from_view.transform_point3(Vec3::ZERO);
        let n = (w * h) as usize;
        let mut position = vec![Vec3::ZERO; n];
        let mut geometric_normal = vec![Vec3::ZERO; n];
        let mut shading_normal = vec![Vec3::ZERO; n];
        let mut depth = vec![f32::INFINITY; n];
        let mut triangle = frags.triangle.clone();
        let normals = scene.shading_normals();
        position
            .par_iter_mut()
            .zip(geometric_normal.par_iter_mut())
            .zip(shading_normal.par_iter_mut())
            .zip(depth.par_iter_mut())
            .zip(triangle.par_iter_mut())
            .enumerate()
            .for_each(|(i, ((((pos, gn), sn), d), tri))| {
                if *tri == NO_TRIANGLE {
                    return;
                }
                let (x, y) = (i as u32 % w, i as u32 / w);
                let (o, dir) = view.pixel_ray(x, y);
                let t = *tri as usize;
                let [a, b, c] = scene.triangle(t);
                let (a64, b64, c64) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
                let n64 = (b64 - a64).cross(c64 - a64);
                let (o64, d64) = (o.as_dvec3(), dir.as_dvec3());
                let denom = n64.dot(d64);
                let hit = if denom != 0.0 {
                    let s = n64.dot(a64 - o64) / denom;
                    o64 + d64 * s
                } else {
                    // Edge-on triangle: fall back to the rasterized depth along the ray.
                    o64 + d64 * frags.depth[i] as f64
                };
                if !hit.is_finite() {
                    *tri = NO_TRIANGLE;
                    return;
                }
                let hit = on_surface(a64, b64, c64, n64, hit);
                let flip = n64.dot(d64) > 0.0;
                let (geo, shading) = surface_normals(scene, normals, t, [a64, b64, c64], hit, flip);
                *pos = hit.as_vec3();
                *gn = geo.as_vec3();
                *sn = shading.as_vec3();
                *d = view.depth_of(*pos);
            });
        Ok(Self {
            width: w,
            height: h,
            camera_position,
            view: Some(*view),
            position,
            geometric_normal,
            shading_normal,
            triangle,
            depth,
            albedo: None,
            unmatched: 0,
            sample_pixels: None,
        })
    }

    /// Every `k`-th view sample each way: the view of [`RasterView::every_kth`], whose pixel
    /// `(x, y)` holds this view's sample `(k x + k / 2, k y + k / 2)` (the same surface point
    /// on the same camera ray), without rasterizing again. A technique chooser's low-resolution
    /// look at the scene costs a copy, not a second view.
    pub fn every_kth(&self, k: u32) -> Self {
        let k = k.max(1);
        let view = self.view.map(|v| v.every_kth(k));
        let (w, h) = match &view {
            Some(v) => (v.width, v.height),
            None => (self.width.div_ceil(k), self.height.div_ceil(k)),
        };
        let n = (w * h) as usize;
        let source = |i: usize| {
            let (x, y) = (i as u32 % w, i as u32 / w);
            let sx = (k * x + k / 2).min(self.width - 1);
            let sy = (k * y + k / 2).min(self.height - 1);
            (sy * self.width + sx) as usize
        };
        Self {
            width: w,
            height: h,
            camera_position: self.camera_position,
            view,
            position: (0..n).map(|i| self.position[source(i)]).collect(),
            geometric_normal: (0..n).map(|i| self.geometric_normal[source(i)]).collect(),
            shading_normal: (0..n).map(|i| self.shading_normal[source(i)]).collect(),
            triangle: (0..n).map(|i| self.triangle[source(i)]).collect(),
            depth: (0..n).map(|i| self.depth[source(i)]).collect(),
            albedo: self
                .albedo
                .as_ref()
                .map(|a| (0..n).map(|i| a[source(i)]).collect()),
            unmatched: (0..n)
                .filter(|&i| self.triangle[source(i)] == FREE_RECEIVER)
                .count() as u64,
            sample_pixels: self
                .sample_pixels
                .as_ref()
                .map(|k| (0..n).map(|i| k[source(i)]).collect()),
        }
    }

    /// The pixel receiver `i`'s light samples are drawn for ([`ViewSample::pixel`]).
    pub(crate) fn sample_pixel(&self, i: usize) -> UVec2 {
        match &self.sample_pixels {
            Some(k) => k[i],
            None => UVec2::new(i as u32 % self.width, i as u32 / self.width),
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }
    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.triangle.len()
    }
    /// True for a 0-pixel buffer (never produced by [`ViewSamples::render`]).
    pub fn is_empty(&self) -> bool {
        self.triangle.is_empty()
    }
    /// Position of the camera (ray origin of perspective views; the origin without a camera).
    pub fn camera_position(&self) -> Vec3 {
        self.camera_position
    }
    /// The camera projection the samples were rendered with, `None` for receivers handed in
    /// without a camera (techniques that rasterize in the camera's image, such as DCS's
    /// shadow-volume and wedge passes, need it).
    pub fn raster_view(&self) -> Option<&RasterView> {
        self.view.as_ref()
    }
    /// The eye point of a perspective view and the view, `None` for an orthographic one or no
    /// camera.
    pub fn perspective(&self) -> Option<(Vec3, &RasterView)> {
        self.eye().zip(self.view.as_ref())
    }
    /// The eye point of a perspective view, `None` for an orthographic one or no camera.
    pub fn eye(&self) -> Option<Vec3> {
        self.view
            .filter(|v| matches!(v.projection, crate::raster::Projection::Perspective { .. }))
            .map(|_| self.camera_position)
    }
    /// Receivers handed in by the caller that matched no surface within its tolerance and
    /// were offset by it ([`crate::receivers`]).
    pub fn unmatched_receivers(&self) -> u64 {
        self.unmatched
    }
    /// True when pixel `i` (row-major) sees a surface.
    pub fn is_valid(&self, i: usize) -> bool {
        self.triangle[i] != NO_TRIANGLE
    }
    /// The valid-pixel mask, row-major.
    pub fn valid_mask(&self) -> Vec<bool> {
        self.triangle.iter().map(|&t| t != NO_TRIANGLE).collect()
    }
    /// Number of valid pixels.
    pub fn valid_count(&self) -> usize {
        self.triangle.iter().filter(|&&t| t != NO_TRIANGLE).count()
    }
    /// The sample of pixel `i`, `None` for background.
    #[inline]
    pub fn get(&self, i: usize) -> Option<ViewSample> {
        self.sample_at(i, UVec2::new(i as u32 % self.width, i as u32 / self.width))
    }
    /// The sample of the pixel at column `x` and row `y` (`x` below the width), `None` for
    /// background: [`ViewSamples::get`] for callers that walk rows, without the division that
    /// recovers the coordinates from the index.
    #[inline]
    pub fn get_at(&self, x: u32, y: u32) -> Option<ViewSample> {
        debug_assert!(
            x < self.width,
            "column {x} outside a width of {}",
            self.width
        );
        self.sample_at(
            y as usize * self.width as usize + x as usize,
            UVec2::new(x, y),
        )
    }
    #[inline]
    fn sample_at(&self, i: usize, pixel: UVec2) -> Option<ViewSample> {
        self.is_valid(i).then(|| ViewSample {
            pixel: self.sample_pixels.as_ref().map_or(pixel, |k| k[i]),
            position: self.position[i],
            geometric_normal: self.geometric_normal[i],
            shading_normal: self.shading_normal[i],
            triangle: self.triangle[i],
            depth: self.depth[i],
            albedo: self.albedo.as_ref().map(|a| a[i]),
        })
    }
    /// Positions, row-major (zero for background).
    pub fn positions(&self) -> &[Vec3] {
        &self.position
    }
    /// Geometric normals, row-major (zero for background).
    pub fn geometric_normals(&self) -> &[Vec3] {
        &self.geometric_normal
    }
    /// Shading normals, row-major (zero for background).
    pub fn shading_normals(&self) -> &[Vec3] {
        &self.shading_normal
    }
    /// Triangle ids, row-major ([`NO_TRIANGLE`] for background).
    pub fn triangles(&self) -> &[u32] {
        &self.triangle
    }
    /// Linear depths, row-major (infinite for background).
    pub fn depths(&self) -> &[f32] {
        &self.depth
    }
}

/// The surface point of triangle `a, b, c` (normal `n`, not unit) for a hit `hit` on its
/// plane. The rasterizer's coverage test admits pixel centres within rounding of an edge,
/// whose ray meets the plane just outside the triangle: a floor point a ULP beyond the foot of
/// a wall lies behind that wall, and every technique drew a line of false shadow along room
/// corners. The closest point of the triangle, moved a hair (2^-20 of the way) toward its
/// centroid, puts it back on the surface the pixel sees and strictly in front of the
/// neighbour. A hit on an edge (up to rounding) is moved the same way: a floor point exactly
/// at the foot of a wall starts its shadow rays in the wall's plane.
pub(crate) fn on_surface(a: DVec3, b: DVec3, c: DVec3, n: DVec3, hit: DVec3) -> DVec3 {
    const HAIR: f64 = 1.0 / 1_048_576.0;
    let on = closest_on_triangle(a, b, c, hit);
    if barycentric(a, b, c, n, on).min_element() < HAIR {
        on + ((a + b + c) / 3.0 - on) * HAIR
    } else {
        on
    }
}

/// The unit geometric and shading normals of triangle `t` (corners `abc`) at `hit`, both
/// flipped when `flip` (to face the viewer or the caller's normal); the shading normal is
/// interpolated from the scene's vertex normals where it has them.
pub(crate) fn surface_normals(
    scene: &dyn Scene,
    normals: Option<&[Vec3]>,
    t: usize,
    [a, b, c]: [DVec3; 3],
    hit: DVec3,
    flip: bool,
) -> (DVec3, DVec3) {
    let n = (b - a).cross(c - a);
    let unflipped = n.normalize();
    let geo = if flip { -unflipped } else { unflipped };
    let shading = match normals {
        Some(ns) => {
            let [ia, ib, ic] = scene.triangles()[t];
            let bary = barycentric(a, b, c, n, hit);
            let s = ns[ia as usize].as_dvec3() * bary.x
                + ns[ib as usize].as_dvec3() * bary.y
                + ns[ic as usize].as_dvec3() * bary.z;
            // Vertex normals that cancel fall back to the face's own normal.
            let s = s.try_normalize().unwrap_or(unflipped);
            if flip { -s } else { s }
        }
        None => geo,
    };
    (geo, shading)
}

/// The point of triangle `abc` closest to `p` (Ericson, "Real-Time Collision Detection",
/// section 5.1.5), `p` itself when it lies over the triangle.
fn closest_on_triangle(a: DVec3, b: DVec3, c: DVec3, p: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    // Inside: keep the ray's hit (it lies in the plane up to rounding already).
    p
}

/// Barycentric coordinates of `p` (on the plane of `a, b, c` with normal `n`).
fn barycentric(a: DVec3, b: DVec3, c: DVec3, n: DVec3, p: DVec3) -> DVec3 {
    let nn = n.length_squared();
    let wa = (c - b).cross(p - b).dot(n) / nn;
    let wb = (a - c).cross(p - c).dot(n) / nn;
    DVec3::new(wa, wb, 1.0 - wa - wb)
}
