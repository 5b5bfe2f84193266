//! View samples (the G-buffer): per pixel the first surface hit through the pixel centre, shared
//! by every technique and the reference so that differences come from shadows alone
//! (DESIGN section 3).
//!
//! The rasterizer decides which triangle a pixel sees; the position is then the exact
//! intersection of the pixel's camera ray with that triangle's plane (computed in f64), so it
//! equals a ray tracer's hit point rather than an interpolated approximation.

use glam::{DVec3, UVec2, Vec3};
use rayon::prelude::*;

use crate::camera::Camera;
use crate::raster::{NO_TRIANGLE, RasterError, RasterView, rasterize};
use crate::scene::Scene;

/// The largest view, in pixels (8192 x 4096): view samples cost about 64 bytes a pixel (2 GiB
/// here), a technique's outputs more (per-sample visibility: `N / 8` bytes a pixel), so a larger
/// request is refused before anything is allocated rather than exhausting memory.
pub const MAX_VIEW_PIXELS: u64 = 1 << 25;
/// The G-buffer of one camera view.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewSamples {
    width: u32,
    height: u32,
    camera_position: Vec3,
    view: RasterView,
    position: Vec<Vec3>,
    geometric_normal: Vec<Vec3>,
    shading_normal: Vec<Vec3>,
    triangle: Vec<u32>,
    depth: Vec<f32>,
}

/// One valid view sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewSample {
    /// Pixel coordinates.
    pub pixel: UVec2,
    /// World position on the surface.
    pub position: Vec3,
    /// Unit geometric normal, flipped to face the camera.
    pub geometric_normal: Vec3,
    /// Unit shading normal (interpolated, on the camera's side like the geometric normal).
    pub shading_normal: Vec3,
    /// Triangle id.
    pub triangle: u32,
    /// Linear depth along the camera axis.
    pub depth: f32,
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
        Self::render_view(scene, &view)
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
                // The rasterizer's coverage test admits pixel centres within rounding of an
                // edge, whose ray meets the plane just outside the triangle: a floor point a
                // ULP beyond the foot of a wall lies behind that wall, and every technique drew
                // a line of false shadow along room corners. The closest point of the
                // triangle, moved a hair (2^-20 of the way) toward its centroid, puts it back
                // on the surface the pixel sees and strictly in front of the neighbour.
                // A hit on an edge (up to rounding) is moved the same way: a floor point
                // exactly at the foot of a wall starts its shadow rays in the wall's plane.
                const HAIR: f64 = 1.0 / 1_048_576.0;
                let on = closest_on_triangle(a64, b64, c64, hit);
                let hit = if barycentric(a64, b64, c64, n64, on).min_element() < HAIR {
                    on + ((a64 + b64 + c64) / 3.0 - on) * HAIR
                } else {
                    on
                };
                let geo = n64.normalize();
                let flip = geo.dot(d64) > 0.0;
                let geo = if flip { -geo } else { geo };
                let shading = match normals {
                    Some(ns) => {
                        let [ia, ib, ic] = scene.triangles()[t];
                        let bary = barycentric(a64, b64, c64, n64, hit);
                        let s = ns[ia as usize].as_dvec3() * bary.x
                            + ns[ib as usize].as_dvec3() * bary.y
                            + ns[ic as usize].as_dvec3() * bary.z;
                        let s = s.try_normalize().unwrap_or(geo);
                        if flip { -s } else { s }
                    }
                    None => geo,
                };
                *pos = hit.as_vec3();
                *gn = geo.as_vec3();
                *sn = shading.as_vec3();
                *d = view.depth_of(*pos);
            });
        Ok(Self {
            width: w,
            height: h,
            camera_position,
            view: *view,
            position,
            geometric_normal,
            shading_normal,
            triangle,
            depth,
        })
    }

    /// Every `k`-th view sample each way: the view of [`RasterView::every_kth`], whose pixel
    /// `(x, y)` holds this view's sample `(k x + k / 2, k y + k / 2)` (the same surface point
    /// on the same camera ray), without rasterizing again. A technique chooser's low-resolution
    /// look at the scene costs a copy, not a second view.
    pub fn every_kth(&self, k: u32) -> Self {
        let k = k.max(1);
        let view = self.view.every_kth(k);
        let (w, h) = (view.width, view.height);
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
    /// Position of the camera (ray origin of perspective views).
    pub fn camera_position(&self) -> Vec3 {
        self.camera_position
    }
    /// The camera projection the samples were rendered with (techniques that rasterize in the
    /// camera's image, such as DCS's shadow-volume and wedge passes, need it).
    pub fn raster_view(&self) -> &RasterView {
        &self.view
    }
    /// The eye point of a perspective view, `None` for an orthographic one.
    pub fn eye(&self) -> Option<Vec3> {
        matches!(
            self.view.projection,
            crate::raster::Projection::Perspective { .. }
        )
        .then_some(self.camera_position)
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
            pixel,
            position: self.position[i],
            geometric_normal: self.geometric_normal[i],
            shading_normal: self.shading_normal[i],
            triangle: self.triangle[i],
            depth: self.depth[i],
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

/// Barycentric coordinates of `p` (on the plane of `a, b, c` with normal `n`).
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

fn barycentric(a: DVec3, b: DVec3, c: DVec3, n: DVec3, p: DVec3) -> DVec3 {
    let nn = n.length_squared();
    let wa = (c - b).cross(p - b).dot(n) / nn;
    let wb = (a - c).cross(p - c).dot(n) / nn;
    DVec3::new(wa, wb, 1.0 - wa - wb)
}
