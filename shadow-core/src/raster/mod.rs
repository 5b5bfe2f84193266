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

    /// The view of `width / k` x `height / k` pixels (at least one each way) whose pixel
    /// `(x, y)` has the centre ray of this view's pixel `(k x + k / 2, k y + k / 2)`, up to
    /// rounding: the extents move by the blocks' offset and cover whole blocks of `k x k`
    /// pixels. `k` of 0 counts as 1.
    pub fn every_kth(&self, k: u32) -> RasterView {
        let k = k.max(1);
        let (w, h) = ((self.width / k).max(1), (self.height / k).max(1));
        let (l, r, b, t, near, persp) = self.extents();
        let (px, py) = ((r - l) / self.width as f32, (t - b) / self.height as f32);
        // The block's chosen pixel centre lies `k / 2 + 1/2` pixels into it, the block's
        // centre `k / 2`: the two differ by half a pixel for even `k`.
        let shift = (k / 2) as f32 + 0.5 - 0.5 * k as f32;
        let left = l + shift * px;
        let top = t - shift * py;
        let right = left + (w * k) as f32 * px;
        let bottom = top - (h * k) as f32 * py;
        let projection = if persp {
            Projection::Perspective {
                left,
                right,
                bottom,
                top,
                near,
            }
        } else {
            Projection::Orthographic {
                left,
                right,
                bottom,
                top,
                near,
            }
        };
        RasterView {
            width: w,
            height: h,
            projection,
            ..*self
        }
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

/// Bounding-box width (pixels, less one) from which a triangle's rows are scanned by their
/// covered runs rather than pixel by pixel.
const SPAN_MIN_WIDTH: u32 = 4;

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
    let k = layers as usize;
    let band_len = (BAND * w) as usize * k;
    let mut tri_out = vec![NO_TRIANGLE; (w * h) as usize * k];
    let mut depth_out = vec![f32::INFINITY; (w * h) as usize * k];
    scan_chunks(positions, triangles, view, |setups, bins| {
        tri_out
            .par_chunks_mut(band_len)
            .zip(depth_out.par_chunks_mut(band_len))
            .enumerate()
            .for_each(|(band, (tri_band, depth_band))| {
                scan_band(
                    setups,
                    &bins[band],
                    band as u32,
                    view,
                    false,
                    |base, t, d| {
                        insert_layer(
                            &mut tri_band[base * k..(base + 1) * k],
                            &mut depth_band[base * k..(base + 1) * k],
                            t,
                            d,
                        );
                    },
                );
            });
    });
    Ok(Fragments {
        width: w,
        height: h,
        layers,
        triangle: tri_out,
        depth: depth_out,
    })
}

/// The depths alone of [`rasterize`] (`layers` per pixel, nearest first, infinite where
/// unused), for shadow maps: the same depths, without the triangle ids' memory and writes.
///
/// # Errors
/// As [`rasterize`].
pub fn rasterize_depth(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    view: &RasterView,
    layers: u32,
) -> Result<Vec<f32>, RasterError> {
    view.validate(layers)?;
    let (w, h) = (view.width, view.height);
    let k = layers as usize;
    let band_len = (BAND * w) as usize * k;
    let mut depth_out = vec![f32::INFINITY; (w * h) as usize * k];
    scan_chunks(positions, triangles, view, |setups, bins| {
        depth_out
            .par_chunks_mut(band_len)
            .enumerate()
            .for_each(|(band, depth_band)| {
                scan_band(
                    setups,
                    &bins[band],
                    band as u32,
                    view,
                    true,
                    |base, _, d| {
                        if k == 1 {
                            // One layer: the nearest depth ([`insert_depth`] on one slot; `d` is
                            // finite, so an equal depth keeps the earlier fragment alike).
                            let slot = &mut depth_band[base];
                            if d < *slot {
                                *slot = d;
                            }
                        } else {
                            insert_depth(&mut depth_band[base * k..(base + 1) * k], d);
                        }
                    },
                );
            });
    });
    Ok(depth_out)
}

/// Sets up `triangles` in chunks, in order (an equal depth keeps the earlier triangle), so
/// that the set-up data held at once stays bounded (set up whole, 8 million triangles took
/// 3 GB), bins each chunk's pieces by band of rows and hands them to `scan`. Each triangle's
/// pieces (none, or up to two after near-plane clipping) stay where its set-up put them: the
/// chunk's list is collected in place, and a bin entry is `2 * triangle + piece`.
fn scan_chunks(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    view: &RasterView,
    mut scan: impl FnMut(&Pieces, &[Vec<u32>]),
) {
    let bands = view.height.div_ceil(BAND) as usize;
    for (c, chunk) in triangles.chunks(RASTER_CHUNK).enumerate() {
        let first = (c * RASTER_CHUNK) as u32;
        // Set-up in parallel; only the pieces that reach a pixel are kept.
        let setups: Vec<Vec<ScreenTriangle>> = chunk
            .par_iter()
            .map(|tri| {
                let v = tri.map(|i| view.view_from_world.transform_point3(positions[i as usize]));
                setup_triangle(v, view)
            })
            .collect();
        // Binning in triangle order.
        let mut bins: Vec<Vec<u32>> = vec![Vec::new(); bands];
        for (n, pieces) in setups.iter().enumerate() {
            for (k, s) in pieces.iter().enumerate() {
                let (y0, y1) = (s.ymin / BAND, s.ymax / BAND);
                for bin in bins.iter_mut().take(y1 as usize + 1).skip(y0 as usize) {
                    bin.push(2 * n as u32 + k as u32);
                }
            }
        }
        scan(&Pieces { first, setups }, &bins);
    }
}

/// A chunk's set-up triangles: per triangle its pieces, the first triangle's id `first`.
struct Pieces {
    first: u32,
    setups: Vec<Vec<ScreenTriangle>>,
}

impl Pieces {
    /// The triangle id and set-up of bin entry `n`.
    fn get(&self, n: u32) -> (u32, &ScreenTriangle) {
        let t = (n / 2) as usize;
        (self.first + t as u32, &self.setups[t][(n % 2) as usize])
    }
}

/// Scan-converts the pieces `bin` of `setups` within band `band` of rows, in order, handing
/// each covered pixel's index within the band, triangle and depth to `put`. With `plane`, the
/// pixels of a wide triangle's covered runs take their depth from its plane
/// ([`setup::ScreenTriangle::depth_on_plane`]): the shadow maps, whose f32 depths agree with
/// the barycentric ones to rounding (`plane_depths_equal_barycentric_depths`; equal on the
/// layered maps of `depth_peeling_layers_are_strictly_ordered_sorted_hits`); the view keeps
/// the barycentric form, which every technique's view samples come from.
fn scan_band(
    setups: &Pieces,
    bin: &[u32],
    band: u32,
    view: &RasterView,
    plane: bool,
    mut put: impl FnMut(usize, u32, f32),
) {
    let w = view.width;
    let y_lo = band * BAND;
    let y_hi = (y_lo + BAND).min(view.height);
    for &n in bin {
        let (t, s) = setups.get(n);
        let ys = s.ymin.max(y_lo);
        let ye = s.ymax.min(y_hi - 1);
        // Wide boxes take each row's covered run (the same pixels as the test at every
        // centre, [`setup::ConvexRows::row_span`]); narrow ones test every pixel, cheaper
        // than finding the run.
        let wide = s.xmax - s.xmin >= SPAN_MIN_WIDTH;
        let gradient = (wide && plane).then(|| s.depth_gradient());
        for y in ys..=ye {
            let (x0, x1) = if wide {
                match s.row_span(y) {
                    Some(run) => run,
                    None => continue,
                }
            } else {
                (s.xmin, s.xmax)
            };
            if let Some(g) = gradient {
                for x in x0..=x1 {
                    if let Some(d) = s.depth_on_plane(g, x, y) {
                        put(((y - y_lo) * w + x) as usize, t, d);
                    }
                }
                continue;
            }
            for x in x0..=x1 {
                let Some(d) = s.depth_at_center(x, y) else {
                    continue;
                };
                put(((y - y_lo) * w + x) as usize, t, d);
            }
        }
    }
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

/// [`insert_layer`] for depths alone: the same positions, since they depend on depths only.
fn insert_depth(depths: &mut [f32], d: f32) {
    let k = depths.len();
    let pos = depths.partition_point(|&x| x < d);
    if pos == k || depths[pos] == d {
        return;
    }
    depths.copy_within(pos..k - 1, pos + 1);
    depths[pos] = d;
}

#[cfg(test)]
mod tests;
