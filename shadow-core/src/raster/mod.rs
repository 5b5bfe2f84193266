//! A CPU depth rasterizer for camera G-buffers and light-space shadow maps.
//!
//! * Perspective (possibly off-centre, as the GBP07 shadow-map frustum of section 3 needs) and
//!   orthographic projections; triangles are clipped against the near plane in view space.
//! * Coverage at pixel centres with the top-left fill rule, so a pixel on an edge shared by two
//!   triangles belongs to exactly one of them; edge functions are evaluated in f64.
//! * Depth is the linear view-space depth (distance along the view axis), interpolated
//!   perspective-correctly (`1/d` is affine in screen space).
//! * `k`-layer depth peeling in one pass: each pixel keeps its `k` nearest fragments with
//!   strictly increasing depth (BCS06 section 4 takes such layers from the light).
//! * Coverage alone (no depth) of world-space triangles ([`CoveredPixels`]) and of whole convex
//!   planar polygons ([`CoveredPolygon`], one run of pixels per row), by bands of rows.
//! * rayon over bands of rows; triangles are visited in index order inside a band and depth ties
//!   keep the first, so the result is identical whatever the thread count.

mod setup;

use glam::{Affine3A, Vec3};
use rayon::prelude::*;
use thiserror::Error;

use setup::{ConvexRows, ScreenPolygon, ScreenTriangle, setup_polygon, setup_triangle};

/// Largest `width * height * layers` the rasterizer accepts (256 Mi fragments).
pub const MAX_FRAGMENTS: u64 = 1 << 28;
const BAND: u32 = 8;

/// Marks a pixel no triangle covers.
pub const NO_TRIANGLE: u32 = u32::MAX;

/// A projection from view space (looking down -Z) to the image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// Perspective: the image spans `x/d` in `[left, right]` and `y/d` in `[bottom, top]`
    /// where `d = -z > near` is the depth.
    Perspective {
        /// Left extent at unit depth.
        left: f32,
        /// Right extent at unit depth.
        right: f32,
        /// Bottom extent at unit depth.
        bottom: f32,
        /// Top extent at unit depth.
        top: f32,
        /// Near clipping depth (> 0).
        near: f32,
    },
    /// Orthographic: the image spans `x` in `[left, right]`, `y` in `[bottom, top]`, depth `d`
    /// above `near`.
    Orthographic {
        /// Left extent.
        left: f32,
        /// Right extent.
        right: f32,
        /// Bottom extent.
        bottom: f32,
        /// Top extent.
        top: f32,
        /// Near clipping depth (may be negative).
        near: f32,
    },
}

/// Everything the rasterizer needs to know about an image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RasterView {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// View from world (rigid for cameras; any affine map for light frusta).
    pub view_from_world: Affine3A,
    /// The projection.
    pub projection: Projection,
}

/// Why a rasterization could not run.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RasterError {
    /// Zero width or height, or too many fragments.
    #[error(
        "image size {width}x{height} with {layers} layers is outside 1..={MAX_FRAGMENTS} fragments"
    )]
    Size {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// Layers.
        layers: u32,
    },
    /// The image holds more pixels than view samples may (see
    /// [`crate::view_samples::MAX_VIEW_PIXELS`] for the memory each costs).
    #[error(
        "image size {width}x{height} is above the largest supported view of {limit} pixels \
         (view samples take about 64 bytes a pixel, techniques' outputs more)"
    )]
    TooManyPixels {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// The limit.
        limit: u64,
    },
    /// The projection has non-finite or empty extents.
    #[error("projection is invalid: {0}")]
    Projection(&'static str),
}

impl RasterView {
    fn validate(&self, layers: u32) -> Result<(), RasterError> {
        let n = self.width as u64 * self.height as u64 * layers as u64;
        if n == 0 || n > MAX_FRAGMENTS {
            return Err(RasterError::Size {
                width: self.width,
                height: self.height,
                layers,
            });
        }
        if !self.view_from_world.is_finite() {
            return Err(RasterError::Projection("view transform is not finite"));
        }
        let (l, r, b, t, near, persp) = self.extents();
        if !(l.is_finite() && r.is_finite() && b.is_finite() && t.is_finite() && near.is_finite()) {
            return Err(RasterError::Projection("non-finite extents"));
        }
        if !(r > l && t > b) {
            return Err(RasterError::Projection("empty extents"));
        }
        if persp && !(near > 0.0) {
            return Err(RasterError::Projection(
                "perspective near plane must be positive",
            ));
        }
        Ok(())
    }

    /// `(left, right, bottom, top, near, is_perspective)`.
    pub fn extents(&self) -> (f32, f32, f32, f32, f32, bool) {
        match self.projection {
            Projection::Perspective {
                left,
                right,
                bottom,
                top,
                near,
            } => (left, right, bottom, top, near, true),
            Projection::Orthographic {
                left,
                right,
                bottom,
                top,
                near,
            } => (left, right, bottom, top, near, false),
        }
    }

    /// The ray through the centre of pixel `(x, y)` (pixel corners at integers, row 0 at the
    /// top), in world space: origin and unit direction.
    pub fn pixel_ray(&self, x: u32, y: u32) -> (Vec3, Vec3) {
        let (l, r, b, t, _, persp) = self.extents();
        let sx = l + (x as f32 + 0.5) / self.width as f32 * (r - l);
        let sy = t - (y as f32 + 0.5) / self.height as f32 * (t - b);
        let world_from_view = self.view_from_world.inverse();
        if persp {
            let o = world_from_view.transform_point3(Vec3::ZERO);
            let d = world_from_view.transform_vector3(Vec3::new(sx, sy, -1.0));
            (o, d.normalize())
        } else {
            let o = world_from_view.transform_point3(Vec3::new(sx, sy, 0.0));
            let d = world_from_view.transform_vector3(Vec3::NEG_Z);
            (o, d.normalize())
        }
    }

    /// Linear depth of a world point in this view.
    pub fn depth_of(&self, p: Vec3) -> f32 {
        -self.view_from_world.transform_point3(p).z
    }
}

/// Calls `f(x, y)` for every pixel whose centre a world-space triangle covers in `view`, with
/// the same near-plane clipping and top-left rule as [`rasterize`]: a pixel centre on an edge
/// shared by two triangles is reported for exactly one of them, whatever their winding. Used by
/// techniques that rasterize volumes into the camera image (DCS's shadow-volume quads, section
/// 4.1, and its wedges, section 4.2).
pub fn for_each_covered_pixel(view: &RasterView, tri: [Vec3; 3], f: impl FnMut(u32, u32)) {
    CoveredPixels::new(view, tri).for_each_in_rows(0, u32::MAX, f);
}

/// A world-space triangle set up once for [`for_each_covered_pixel`]'s coverage (near-plane
/// clipping, top-left rule), so that a caller can visit its pixels one band of rows at a time:
/// bands of an image then accumulate in parallel, each into its own rows.
#[derive(Debug, Clone)]
pub struct CoveredPixels {
    parts: Vec<ScreenTriangle>,
}

impl CoveredPixels {
    /// Sets up `tri` in `view`.
    pub fn new(view: &RasterView, tri: [Vec3; 3]) -> Self {
        let v = tri.map(|p| view.view_from_world.transform_point3(p));
        Self {
            parts: setup_triangle(v, view),
        }
    }

    /// The first and last rows that may hold covered pixels; `None` when none can.
    pub fn rows(&self) -> Option<(u32, u32)> {
        let lo = self.parts.iter().map(|s| s.ymin).min()?;
        let hi = self.parts.iter().map(|s| s.ymax).max()?;
        Some((lo, hi))
    }

    /// Calls `f(y, x0, x1)` for every row `y` in `y0..=y1` with covered pixels, each run
    /// `x0..=x1` of covered pixels once (a part of the set-up covers one run per row, so a
    /// triangle split by the near plane may give two). The same pixels as
    /// [`CoveredPixels::for_each_in_rows`]: the run's ends are found by the exact coverage test,
    /// every pixel between them is covered (coverage along a row is an interval).
    pub fn for_each_span_in_rows(&self, y0: u32, y1: u32, mut f: impl FnMut(u32, u32, u32)) {
        for st in &self.parts {
            for y in st.ymin.max(y0)..=st.ymax.min(y1) {
                if let Some((x0, x1)) = st.row_span(y) {
                    f(y, x0, x1);
                }
            }
        }
    }

    /// Calls `f(x, y)` for every covered pixel in rows `y0..=y1`.
    pub fn for_each_in_rows(&self, y0: u32, y1: u32, mut f: impl FnMut(u32, u32)) {
        for st in &self.parts {
            for y in st.ymin.max(y0)..=st.ymax.min(y1) {
                let Some((x0, x1)) = st.row_candidates(y) else {
                    continue;
                };
                for x in x0..=x1 {
                    if st.covers(x, y) {
                        f(x, y);
                    }
                }
            }
        }
    }
}

/// A world-space convex planar polygon set up whole for scan conversion, with the coverage of
/// [`CoveredPixels`] (near-plane clipping, top-left rule on each edge): the pixels of the union
/// of its fan triangles, each once, but one run per row for the whole polygon instead of one
/// per triangle. DCS's shadow-volume quads (section 4.1) are rasterized this way.
#[derive(Debug, Clone)]
pub struct CoveredPolygon {
    part: Option<ScreenPolygon>,
}

impl CoveredPolygon {
    /// Sets up the convex planar polygon `outline` (vertices in order, either winding) in
    /// `view`.
    pub fn new(view: &RasterView, outline: &[Vec3]) -> Self {
        let v: Vec<Vec3> = outline
            .iter()
            .map(|p| view.view_from_world.transform_point3(*p))
            .collect();
        Self {
            part: setup_polygon(&v, view),
        }
    }

    /// The first and last rows that may hold covered pixels; `None` when none can.
    pub fn rows(&self) -> Option<(u32, u32)> {
        self.part.as_ref().map(|s| (s.ymin, s.ymax))
    }

    /// Calls `f(y, x0, x1)` for every row `y` in `y0..=y1` with covered pixels, with its run
    /// `x0..=x1` of covered pixels (coverage along a row of a convex polygon is an interval).
    pub fn for_each_span_in_rows(&self, y0: u32, y1: u32, mut f: impl FnMut(u32, u32, u32)) {
        if let Some(st) = &self.part {
            for y in st.ymin.max(y0)..=st.ymax.min(y1) {
                if let Some((x0, x1)) = st.row_span(y) {
                    f(y, x0, x1);
                }
            }
        }
    }

    /// True when the polygon covers the centre of pixel `(x, y)`.
    pub fn covers(&self, x: u32, y: u32) -> bool {
        self.part.as_ref().is_some_and(|s| {
            (s.xmin..=s.xmax).contains(&x) && (s.ymin..=s.ymax).contains(&y) && s.covers(x, y)
        })
    }
}

/// The fragments kept per pixel: triangle ids and linear depths, `layers` per pixel, nearest
/// first. Unused layers hold [`NO_TRIANGLE`] and `f32::INFINITY`.
#[derive(Debug, Clone, PartialEq)]
pub struct Fragments {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Layers per pixel.
    pub layers: u32,
    /// Triangle id per (pixel, layer): index `(y * width + x) * layers + layer`.
    pub triangle: Vec<u32>,
    /// Linear depth per (pixel, layer).
    pub depth: Vec<f32>,
}

impl Fragments {
    /// Triangle id of layer `layer` at pixel `(x, y)`.
    pub fn triangle_at(&self, x: u32, y: u32, layer: u32) -> u32 {
        self.triangle[((y * self.width + x) * self.layers + layer) as usize]
    }
    /// Depth of layer `layer` at pixel `(x, y)`.
    pub fn depth_at(&self, x: u32, y: u32, layer: u32) -> f32 {
        self.depth[((y * self.width + x) * self.layers + layer) as usize]
    }
}

/// Triangles set up at once by [`rasterize`].
const RASTER_CHUNK: usize = 1 << 18;

/// Rasterizes `triangles` (indices into `positions`) into `layers` depth layers.
///
/// # Errors
/// [`RasterError`] for an invalid view or size. Positions are assumed finite (scenes are
/// validated); non-finite projected vertices drop their triangle.
pub fn rasterize(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    view: &RasterView,
    layers: u32,
) -> Result<Fragments, RasterError> {
    view.validate(layers)?;
    let (w, h) = (view.width, view.height);
    let bands = h.div_ceil(BAND) as usize;
    let k = layers as usize;
    let band_len = (BAND * w) as usize * k;
    let mut tri_out = vec![NO_TRIANGLE; (w * h) as usize * k];
    let mut depth_out = vec![f32::INFINITY; (w * h) as usize * k];
    // Triangles go through in chunks, in order (an equal depth keeps the earlier triangle), so
    // the set-up data held at once stays bounded: set up whole, 8 million triangles took 3 GB.
    for (c, chunk) in triangles.chunks(RASTER_CHUNK).enumerate() {
        let first = (c * RASTER_CHUNK) as u32;
        // Set-up in parallel; only the pieces that reach a pixel are kept.
        let setups: Vec<(u32, ScreenTriangle)> = chunk
            .par_iter()
            .enumerate()
            .flat_map_iter(|(i, tri)| {
                let v = tri.map(|i| view.view_from_world.transform_point3(positions[i as usize]));
                setup_triangle(v, view)
                    .into_iter()
                    .map(move |s| (first + i as u32, s))
            })
            .collect();
        // Binning in triangle order.
        let mut bins: Vec<Vec<u32>> = vec![Vec::new(); bands];
        for (n, (_, s)) in setups.iter().enumerate() {
            let (y0, y1) = (s.ymin / BAND, s.ymax / BAND);
            for bin in bins.iter_mut().take(y1 as usize + 1).skip(y0 as usize) {
                bin.push(n as u32);
            }
        }
        tri_out
            .par_chunks_mut(band_len)
            .zip(depth_out.par_chunks_mut(band_len))
            .enumerate()
            .for_each(|(band, (tri_band, depth_band))| {
                let y_lo = band as u32 * BAND;
                let y_hi = (y_lo + BAND).min(h);
                for &n in &bins[band] {
                    let (t, s) = &setups[n as usize];
                    let ys = s.ymin.max(y_lo);
                    let ye = s.ymax.min(y_hi - 1);
                    for y in ys..=ye {
                        for x in s.xmin..=s.xmax {
                            let Some(d) = s.depth_at_center(x, y) else {
                                continue;
                            };
                            let base = (((y - y_lo) * w + x) as usize) * k;
                            insert_layer(
                                &mut tri_band[base..base + k],
                                &mut depth_band[base..base + k],
                                *t,
                                d,
                            );
                        }
                    }
                }
            });
    }
    Ok(Fragments {
        width: w,
        height: h,
        layers,
        triangle: tri_out,
        depth: depth_out,
    })
}

/// Inserts a fragment into a pixel's sorted layer list, keeping depths strictly increasing
/// (an equal depth keeps the earlier triangle).
fn insert_layer(tris: &mut [u32], depths: &mut [f32], t: u32, d: f32) {
    let k = tris.len();
    let pos = depths.partition_point(|&x| x < d);
    if pos == k || depths[pos] == d {
        return;
    }
    for i in (pos + 1..k).rev() {
        tris[i] = tris[i - 1];
        depths[i] = depths[i - 1];
    }
    tris[pos] = t;
    depths[pos] = d;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layer_insertion_keeps_strict_order() {
        let mut t = [NO_TRIANGLE; 3];
        let mut d = [f32::INFINITY; 3];
        for (id, depth) in [(0, 5.0), (1, 2.0), (2, 5.0), (3, 9.0), (4, 1.0)] {
            insert_layer(&mut t, &mut d, id, depth);
        }
        assert_eq!(t, [4, 1, 0]);
        assert_eq!(d, [1.0, 2.0, 5.0]);
    }

    #[test]
    fn invalid_views_are_errors() {
        let view = RasterView {
            width: 0,
            height: 4,
            view_from_world: Affine3A::IDENTITY,
            projection: Projection::Orthographic {
                left: -1.0,
                right: 1.0,
                bottom: -1.0,
                top: 1.0,
                near: 0.0,
            },
        };
        assert!(rasterize(&[], &[], &view, 1).is_err());
        let v = RasterView {
            width: 4,
            projection: Projection::Perspective {
                left: 1.0,
                right: -1.0,
                bottom: -1.0,
                top: 1.0,
                near: 0.1,
            },
            ..view
        };
        assert!(matches!(
            rasterize(&[], &[], &v, 1),
            Err(RasterError::Projection(_))
        ));
    }

    /// Triangles are set up a chunk at a time; the layers must not see the chunks: an equal
    /// depth keeps the earlier triangle and a nearer one goes first, across chunk borders too.
    #[test]
    fn chunks_keep_triangle_order_and_layers() {
        let view = ortho_view();
        // Two copies of one square at depth 2, the second in the next chunk, one at depth 1 in
        // the chunk after, and off-screen triangles in between.
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        let square = |positions: &mut Vec<Vec3>, z: f32| {
            let b = positions.len() as u32;
            positions.extend([
                Vec3::new(4.0, 4.0, z),
                Vec3::new(28.0, 4.0, z),
                Vec3::new(28.0, 28.0, z),
                Vec3::new(4.0, 28.0, z),
            ]);
            [[b, b + 1, b + 2], [b, b + 2, b + 3]]
        };
        triangles.extend(square(&mut positions, -2.0));
        let off = positions.len() as u32;
        positions.extend([
            Vec3::new(100.0, 100.0, -2.0),
            Vec3::new(101.0, 100.0, -2.0),
            Vec3::new(100.0, 101.0, -2.0),
        ]);
        triangles.resize(RASTER_CHUNK + 3, [off, off + 1, off + 2]);
        let second = triangles.len() as u32;
        triangles.extend(square(&mut positions, -2.0));
        triangles.resize(2 * RASTER_CHUNK + 7, [off, off + 1, off + 2]);
        let third = triangles.len() as u32;
        triangles.extend(square(&mut positions, -1.0));
        let f = rasterize(&positions, &triangles, &view, 3).unwrap();
        for (x, y) in [(10, 10), (20, 25), (5, 27)] {
            let t = f.triangle_at(x, y, 0);
            assert!(t == third || t == third + 1, "({x}, {y}): {t}");
            assert_eq!(f.depth_at(x, y, 0), 1.0);
            assert!(
                f.triangle_at(x, y, 1) < 2,
                "({x}, {y}): {}",
                f.triangle_at(x, y, 1)
            );
            assert_eq!(f.depth_at(x, y, 1), 2.0);
            assert_eq!(f.triangle_at(x, y, 2), NO_TRIANGLE);
        }
        assert!(second > RASTER_CHUNK as u32 && third > 2 * RASTER_CHUNK as u32);
    }

    /// A perspective view of 37 x 29 pixels with the near plane at 0.1.
    fn persp_view() -> RasterView {
        RasterView {
            width: 37,
            height: 29,
            view_from_world: Affine3A::IDENTITY,
            projection: Projection::Perspective {
                left: -1.0,
                right: 1.0,
                bottom: -0.8,
                top: 0.8,
                near: 0.1,
            },
        }
    }

    /// An orthographic view of 32 x 32 pixels over `[0, 32]^2`.
    fn ortho_view() -> RasterView {
        RasterView {
            width: 32,
            height: 32,
            view_from_world: Affine3A::IDENTITY,
            projection: Projection::Orthographic {
                left: 0.0,
                right: 32.0,
                bottom: 0.0,
                top: 32.0,
                near: 0.1,
            },
        }
    }

    /// Visiting a triangle band by band reports the same pixels, once each, as one visit of
    /// the whole image, a triangle clipped by the near plane included.
    #[test]
    fn covered_pixels_by_bands_equal_the_whole_visit() {
        let view = persp_view();
        // Random triangles too, some crossing the near plane, some thin.
        let r = |k: u64, i: u64| {
            crate::sampling::unit_float(crate::sampling::hash_words(&[k, i])) * 2.0 - 1.0
        };
        let random = (0..300u64).map(|k| {
            std::array::from_fn(|v| {
                let v = v as u64;
                Vec3::new(
                    r(k, 3 * v) * 2.0,
                    r(k, 3 * v + 1) * 2.0,
                    -2.0 + 1.8 * r(k, 3 * v + 2),
                )
            })
        });
        let fixed = [
            [
                Vec3::new(-3.0, -2.0, -4.0),
                Vec3::new(2.5, -1.0, -3.0),
                Vec3::new(0.2, 3.0, -5.0),
            ],
            // Crosses the near plane.
            [
                Vec3::new(-0.5, -0.5, 1.0),
                Vec3::new(0.7, -0.2, -2.0),
                Vec3::new(0.1, 0.9, -2.5),
            ],
            // A sliver.
            [
                Vec3::new(-2.0, -1.0, -3.0),
                Vec3::new(2.0, 1.0, -3.0),
                Vec3::new(2.0, 1.01, -3.0),
            ],
        ];
        let mut covered = 0;
        for (t, tri) in fixed.into_iter().chain(random).enumerate() {
            let mut whole = Vec::new();
            for_each_covered_pixel(&view, tri, |x, y| whole.push((x, y)));
            let cover = CoveredPixels::new(&view, tri);
            let Some((lo, hi)) = cover.rows() else {
                assert!(t >= 3 && whole.is_empty(), "triangle {t}");
                continue;
            };
            let mut banded = Vec::new();
            for y0 in (0..view.height).step_by(4) {
                cover.for_each_in_rows(y0, y0 + 3, |x, y| {
                    assert!((y0..y0 + 4).contains(&y) && (lo..=hi).contains(&y));
                    banded.push((x, y));
                });
            }
            assert!(t >= 3 || !whole.is_empty());
            covered += usize::from(!whole.is_empty());
            whole.sort_unstable();
            banded.sort_unstable();
            let n = banded.len();
            banded.dedup();
            assert_eq!(n, banded.len(), "a pixel reported twice");
            assert_eq!(whole, banded);
            // The same pixels as runs.
            let mut spans = Vec::new();
            cover.for_each_span_in_rows(0, view.height, |y, x0, x1| {
                spans.extend((x0..=x1).map(|x| (x, y)));
            });
            spans.sort_unstable();
            assert_eq!(whole, spans, "runs of triangle {t}");
        }
        assert!(covered > 100, "{covered}");
    }

    /// Rows whose pixel centres lie exactly on triangle edges (an orthographic view of 32 x 32
    /// pixels over `[0, 32]^2`, vertices on the half-pixel grid): runs equal the per-pixel
    /// visit, ties included.
    #[test]
    fn row_runs_settle_ties_like_the_pixel_test() {
        let view = ortho_view();
        let mut ties = 0;
        for k in 0..400u64 {
            let r = |i: u64| crate::sampling::hash_words(&[k, i]) % 65;
            // Vertices on multiples of a half pixel, some outside the image.
            let tri: [Vec3; 3] = std::array::from_fn(|v| {
                let v = v as u64;
                Vec3::new(
                    r(2 * v) as f32 * 0.5 - 0.25,
                    r(2 * v + 1) as f32 * 0.5 - 0.25,
                    -1.0,
                )
            });
            let mut whole = Vec::new();
            for_each_covered_pixel(&view, tri, |x, y| whole.push((x, y)));
            let mut spans = Vec::new();
            CoveredPixels::new(&view, tri).for_each_span_in_rows(0, 31, |y, x0, x1| {
                spans.extend((x0..=x1).map(|x| (x, y)));
            });
            whole.sort_unstable();
            spans.sort_unstable();
            assert_eq!(whole, spans, "triangle {k}: {tri:?}");
            // Count pixels whose centre lies on an edge line.
            ties += whole
                .iter()
                .filter(|(x, y)| {
                    let c = glam::Vec2::new(*x as f32 + 0.5, 31.5 - *y as f32);
                    (0..3).any(|i| {
                        let (a, b) = (tri[i].truncate(), tri[(i + 1) % 3].truncate());
                        (b - a).perp_dot(c - a) == 0.0
                    })
                })
                .count();
        }
        assert!(ties > 50, "{ties} pixels on an edge");
    }

    /// The pixels `CoveredPixels` reports for the fan triangles of `outline`.
    fn fan_pixels(view: &RasterView, outline: &[Vec3]) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        for j in 1..outline.len() - 1 {
            let tri = [outline[0], outline[j], outline[j + 1]];
            CoveredPixels::new(view, tri).for_each_in_rows(0, u32::MAX, |x, y| out.push((x, y)));
        }
        out.sort_unstable();
        out
    }

    /// The runs of `outline` as a whole polygon, checked against its per-pixel test.
    fn polygon_pixels(view: &RasterView, outline: &[Vec3]) -> Vec<(u32, u32)> {
        let cover = CoveredPolygon::new(view, outline);
        let mut out = Vec::new();
        cover.for_each_span_in_rows(0, view.height, |y, x0, x1| {
            out.extend((x0..=x1).map(|x| (x, y)));
        });
        out.sort_unstable();
        let mut tested: Vec<(u32, u32)> = (0..view.height)
            .flat_map(|y| (0..view.width).map(move |x| (x, y)))
            .filter(|&(x, y)| cover.covers(x, y))
            .collect();
        tested.sort_unstable();
        assert_eq!(out, tested, "runs and the pixel test of {outline:?}");
        out
    }

    /// A whole convex polygon covers the pixels of its fan triangles, each once: random
    /// planar quads and pentagons in perspective (some crossing the near plane, some thin), and
    /// quads with vertices on the half-pixel grid, whose pixel centres lie on edges (the
    /// top-left rule settles them as for the triangles). Such a quad and a triangle sharing one of
    /// its edges cover each pixel of their union once.
    #[test]
    fn repeated_vertices_do_not_empty_a_covered_polygon() {
        // Clipping at a box corner repeats a vertex, exactly or to the last bits; the repeat
        // made every pixel fail the edge test of the zero-length edge (DCS's shadow-volume
        // quads on the Cornell box counted nowhere).
        let persp = persp_view();
        let quad = vec![
            Vec3::new(-0.5, -0.4, -2.0),
            Vec3::new(0.6, -0.3, -2.0),
            Vec3::new(0.5, 0.5, -2.2),
            Vec3::new(-0.4, 0.4, -2.2),
        ];
        let clean = polygon_pixels(&persp, &quad);
        assert!(!clean.is_empty());
        let near = |v: Vec3| Vec3::new(v.x, f32::from_bits(v.y.to_bits() + 1), v.z);
        for repeated in [
            vec![quad[0], quad[1], quad[1], quad[2], quad[3]],
            vec![quad[0], quad[1], quad[2], quad[3], quad[3], quad[0]],
            vec![
                quad[0],
                quad[1],
                near(quad[1]),
                quad[2],
                quad[3],
                near(quad[3]),
            ],
        ] {
            assert_eq!(polygon_pixels(&persp, &repeated), clean, "{repeated:?}");
        }
    }

    #[test]
    fn covered_polygons_equal_their_fan_triangles() {
        let persp = persp_view();
        let r = |k: u64, i: u64| {
            crate::sampling::unit_float(crate::sampling::hash_words(&[k, i])) * 2.0 - 1.0
        };
        let mut covered = 0;
        for k in 0..300u64 {
            // A convex outline: points on an ellipse at increasing angles, in a tilted plane.
            let n = 4 + (k % 2) as usize;
            let (cx, cy, cz) = (r(k, 0), r(k, 1), -2.0 + 1.8 * r(k, 2));
            let (ra, rb) = (0.2 + 2.0 * r(k, 3).abs(), 0.01 + 1.5 * r(k, 4).abs());
            let (tx, ty) = (r(k, 5), r(k, 6));
            let outline: Vec<Vec3> = (0..n)
                .map(|j| {
                    let t =
                        (j as f32 + 0.4 * r(k, 10 + j as u64)) * std::f32::consts::TAU / n as f32;
                    let (u, v) = (ra * t.cos(), rb * t.sin());
                    Vec3::new(cx + u, cy + v, cz + tx * u + ty * v)
                })
                .collect();
            let fan = fan_pixels(&persp, &outline);
            let whole = polygon_pixels(&persp, &outline);
            let mut dedup = fan.clone();
            dedup.dedup();
            assert_eq!(
                dedup.len(),
                fan.len(),
                "polygon {k}: a fan pixel reported twice"
            );
            assert_eq!(whole, fan, "polygon {k}: {outline:?}");
            covered += usize::from(!whole.is_empty());
        }
        assert!(covered > 100, "{covered}");
        let ortho = ortho_view();
        let (mut shared, mut on_edge) = (0, 0);
        for k in 0..400u64 {
            let g = |i: u64| (crate::sampling::hash_words(&[k, i]) % 65) as f32 * 0.5 - 0.25;
            // A convex quad on the half-pixel grid: a triangle's vertices and a fourth beyond
            // its first edge, kept when the outline stays convex.
            let (a, b, c) = (
                Vec3::new(g(0), g(1), -1.0),
                Vec3::new(g(2), g(3), -1.0),
                Vec3::new(g(4), g(5), -1.0),
            );
            let d = Vec3::new(g(6), g(7), -1.0);
            let turn = |p: Vec3, q: Vec3, s: Vec3| (q - p).truncate().perp_dot((s - q).truncate());
            let outline = [a, d, b, c];
            let signs = [turn(a, d, b), turn(d, b, c), turn(b, c, a), turn(c, a, d)];
            if !(signs.iter().all(|&t| t > 0.0) || signs.iter().all(|&t| t < 0.0)) {
                continue;
            }
            let whole = polygon_pixels(&ortho, &outline);
            assert_eq!(whole, fan_pixels(&ortho, &outline), "quad {k}: {outline:?}");
            // Its neighbour across the edge b c (the mirror of a and d through that edge's
            // midpoint): together they cover each pixel once.
            let m = (b + c) * 0.5;
            let other = [b, c, 2.0 * m - a];
            let mut both = whole.clone();
            both.extend(polygon_pixels(&ortho, &other));
            let n = both.len();
            both.sort_unstable();
            both.dedup();
            assert_eq!(n, both.len(), "quad {k} and its neighbour share a pixel");
            shared += 1;
            // Pixels whose centre lies on the shared edge (y flipped: row 0 is the top).
            on_edge += both
                .iter()
                .filter(|(x, y)| {
                    let p = glam::Vec2::new(*x as f32 + 0.5, 31.5 - *y as f32);
                    (c - b).truncate().perp_dot(p - b.truncate()) == 0.0
                })
                .count();
        }
        assert!(shared > 50, "{shared}");
        assert!(on_edge > 20, "{on_edge} pixels on a shared edge");
    }
}
