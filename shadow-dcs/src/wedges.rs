//! Penumbra wedges (DCS section 4.2): for each silhouette edge, the view samples from which the
//! edge, seen toward the light, covers part of it.
//!
//! The wedge of edge `e` is the set of points `x + t (x - y)`, `x` on the edge, `y` on the
//! light, `t > 0`. For a fixed `t` this is an affine image of `e x L`, so up to a parameter
//! `T` the wedge lies in the convex hull of the edge and the points `(1 + T) v - T l` for the
//! edge's end points `v` and the points `l` whose hull holds the light; `T` is chosen so that
//! anything further lies beyond every view sample. The hull, clipped to the camera's near plane,
//! is projected and scan-converted in the camera image (the screen is the spatial structure that
//! finds the view samples inside, as the GPU rasterizes wedges); each pixel found gets the exact
//! per-sample weight `k_e(p)` (`SceneEdge::sweep_weight`), and only pixels with
//! a non-zero weight are kept. The shadow-volume quad splits the wedge: `k_e > 0` is the outer
//! part (samples beyond the projected edge gain depth complexity), `k_e < 0` the inner part.

use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;
use shadow_core::raster::RasterView;

use crate::edges::SceneEdge;
use crate::light_shape::LightShape;

/// The (pixel, edge, weight) pairs of a band of rows, grouped by pixel in edge order (CSR).
#[derive(Debug, Default)]
pub(crate) struct WedgePairs {
    /// First pixel of the band.
    pub first: usize,
    /// `start[i]..start[i + 1]` indexes the entries of band pixel `i`.
    pub start: Vec<u32>,
    /// Silhouette edge index (into the scene edge list) and its weight at the pixel.
    pub entries: Vec<(u32, i32)>,
    /// Pixels scanned inside wedge hulls (before the exact test).
    pub scanned: u64,
}

impl WedgePairs {
    /// The entries of pixel `i` (image index, inside the band).
    pub fn of(&self, i: usize) -> &[(u32, i32)] {
        let j = i - self.first;
        &self.entries[self.start[j] as usize..self.start[j + 1] as usize]
    }
}

/// The screen region of one wedge.
#[derive(Debug, Clone)]
pub(crate) struct Region {
    edge: u32,
    /// Convex polygon in pixel units; `None` scans the whole image.
    poly: Option<Vec<DVec2>>,
    rows: (u32, u32),
}

/// The screen regions of every silhouette edge's wedge, in edge order (empty regions dropped).
/// The number of unbounded wedges (scanned over the whole image) is returned too.
pub(crate) fn wedge_regions(
    edges: &[SceneEdge],
    silhouettes: &[u32],
    light: &LightShape,
    view: &RasterView,
    origins: &[Vec3],
    active: &[bool],
) -> (Vec<Region>, u64) {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for (p, v) in origins.iter().zip(active) {
        if *v {
            lo = lo.min(p.as_dvec3());
            hi = hi.max(p.as_dvec3());
        }
    }
    if lo.x > hi.x {
        return (Vec::new(), 0);
    }
    let c = light.center.as_dvec3();
    let hull: Vec<DVec3> = light.hull.iter().map(|p| p.as_dvec3()).collect();
    let regions: Vec<Region> = silhouettes
        .par_iter()
        .filter_map(|&ei| {
            let e = &edges[ei as usize];
            match screen_region(e, &hull, c, light.radius as f64, lo, hi, view) {
                None => Some(Region {
                    edge: ei,
                    poly: None,
                    rows: (0, view.height - 1),
                }),
                Some(poly) => {
                    let rows = polygon_rows(&poly, view.height)?;
                    Some(Region {
                        edge: ei,
                        poly: Some(poly),
                        rows,
                    })
                }
            }
        })
        .collect();
    let unbounded = regions.iter().filter(|r| r.poly.is_none()).count() as u64;
    (regions, unbounded)
}

/// The pairs of rows `rows` (a band): every region overlapping the band is scanned there, and
/// each active pixel with a non-zero weight `k_e(p)` is kept.
pub(crate) fn band_pairs(
    edges: &[SceneEdge],
    regions: &[Region],
    c: DVec3,
    view: &RasterView,
    rows: (u32, u32),
    origins: &[Vec3],
    active: &[bool],
) -> WedgePairs {
    let w = view.width as usize;
    let first = rows.0 as usize * w;
    let n = (rows.1 - rows.0 + 1) as usize * w;
    let mut found: Vec<(u32, u32, i32)> = Vec::new();
    let mut scanned = 0u64;
    for r in regions {
        if r.rows.1 < rows.0 || r.rows.0 > rows.1 {
            continue;
        }
        let e = &edges[r.edge as usize];
        let mut visit = |x: u32, y: u32| {
            let i = y as usize * w + x as usize;
            scanned += 1;
            if !active[i] {
                return;
            }
            if let Some(k) = e.sweep_weight(origins[i].as_dvec3(), c, false)
                && k != 0
            {
                let k = k.clamp(i32::MIN as i64, i32::MAX as i64) as i32;
                found.push(((i - first) as u32, r.edge, k));
            }
        };
        match &r.poly {
            Some(poly) => scan_polygon(poly, view.width, rows, &mut visit),
            None => {
                for y in rows.0..=rows.1 {
                    for x in 0..view.width {
                        visit(x, y);
                    }
                }
            }
        }
    }
    let mut start = vec![0u32; n + 1];
    for (j, _, _) in &found {
        start[*j as usize + 1] += 1;
    }
    for j in 0..n {
        start[j + 1] += start[j];
    }
    let mut fill = start.clone();
    let mut entries = vec![(0u32, 0i32); found.len()];
    for (j, e, k) in found {
        let slot = &mut fill[j as usize];
        entries[*slot as usize] = (e, k);
        *slot += 1;
    }
    WedgePairs {
        first,
        start,
        entries,
        scanned,
    }
}

/// Rows whose centres a convex polygon may cover, `None` when none.
fn polygon_rows(poly: &[DVec2], height: u32) -> Option<(u32, u32)> {
    if poly.is_empty() {
        return None;
    }
    let (ymin, ymax) = poly
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.y), b.max(p.y))
        });
    let y0 = (ymin - PAD - 0.5).ceil().max(0.0);
    let y1 = (ymax + PAD - 0.5).floor().min(height as f64 - 1.0);
    (y0 <= y1).then_some((y0 as u32, y1 as u32))
}

/// The screen polygon (pixel units, convex) holding the projection of the wedge's part inside
/// the box `lo..hi`, or `None` when the wedge cannot be bounded (the edge touches the light's
/// bounding ball): the whole image is then scanned.
fn screen_region(
    e: &SceneEdge,
    hull: &[DVec3],
    c: DVec3,
    light_radius: f64,
    lo: DVec3,
    hi: DVec3,
    view: &RasterView,
) -> Option<Vec<DVec2>> {
    // Distance from the edge to the light's ball bounds |x - y| from below.
    let ab = e.b - e.a;
    let t = ((c - e.a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
    let gap = (e.a + ab * t - c).length() - light_radius;
    if !(gap > 0.0) {
        return None;
    }
    let corners = [lo, hi, e.a, e.b];
    let (blo, bhi) = corners.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(l, h), p| (l.min(*p), h.max(*p)),
    );
    let reach = (bhi - blo).length() * 1.001 + 1e-9;
    let big_t = reach / gap;
    let mut pts = Vec::with_capacity(2 + 2 * hull.len());
    pts.push(e.a);
    pts.push(e.b);
    for v in [e.a, e.b] {
        for l in hull {
            pts.push(v * (1.0 + big_t) - *l * big_t);
        }
    }
    let to_view = view.view_from_world;
    let m = glam::Mat4::from(to_view).as_dmat4();
    let vp: Vec<DVec3> = pts.iter().map(|p| m.transform_point3(*p)).collect();
    let (l, r, b, tp, near, persp) = view.extents();
    let near = near as f64;
    // Clip the point cloud's hull against depth >= near: points in front, plus the crossings
    // of every segment from a point in front to a point behind.
    let depth = |q: &DVec3| -q.z;
    let mut kept: Vec<DVec3> = vp.iter().copied().filter(|q| depth(q) >= near).collect();
    let behind: Vec<DVec3> = vp.iter().copied().filter(|q| depth(q) < near).collect();
    if !behind.is_empty() {
        let front = kept.clone();
        for f in &front {
            for bq in &behind {
                let (df, db) = (depth(f) - near, depth(bq) - near);
                let s = df / (df - db);
                let mut q = *f + (*bq - *f) * s;
                q.z = -near;
                kept.push(q);
            }
        }
    }
    if kept.is_empty() {
        return Some(Vec::new());
    }
    let (w, h) = (view.width as f64, view.height as f64);
    let (l, r, b, tp) = (l as f64, r as f64, b as f64, tp as f64);
    let screen: Vec<DVec2> = kept
        .iter()
        .map(|q| {
            let d = -q.z;
            let (x, y) = if persp {
                (q.x / d, q.y / d)
            } else {
                (q.x, q.y)
            };
            DVec2::new((x - l) / (r - l) * w, (tp - y) / (tp - b) * h)
        })
        .collect();
    if screen.iter().any(|p| !p.is_finite()) {
        return None;
    }
    Some(convex_hull(screen))
}

/// Andrew's monotone chain; counter-clockwise in a y-up frame (orientation is irrelevant to the
/// scan).
fn convex_hull(mut p: Vec<DVec2>) -> Vec<DVec2> {
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<DVec2> = Vec::with_capacity(p.len() * 2);
    for pass in 0..2 {
        let start = hull.len();
        let it: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in it {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}

/// Slack in pixels around wedge polygons.
const PAD: f64 = 0.01;

/// Visits the pixels of rows `rows` whose centres lie inside (or within [`PAD`] of) the convex
/// polygon `poly`.
fn scan_polygon(poly: &[DVec2], width: u32, rows: (u32, u32), visit: &mut impl FnMut(u32, u32)) {
    let Some((y0, y1)) = polygon_rows(poly, u32::MAX) else {
        return;
    };
    let (y0, y1) = (y0.max(rows.0), y1.min(rows.1));
    let n = poly.len();
    for y in y0..=y1 {
        let yc = y as f64 + 0.5;
        let (mut xl, mut xr) = (f64::INFINITY, f64::NEG_INFINITY);
        if n < 3 {
            for p in poly {
                xl = xl.min(p.x);
                xr = xr.max(p.x);
            }
        }
        for i in 0..n {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            if yc < a.y.min(b.y) - PAD || yc > a.y.max(b.y) + PAD {
                continue;
            }
            if (b.y - a.y).abs() < 1e-12 {
                xl = xl.min(a.x.min(b.x));
                xr = xr.max(a.x.max(b.x));
            } else {
                let t = ((yc - a.y) / (b.y - a.y)).clamp(0.0, 1.0);
                let x = a.x + (b.x - a.x) * t;
                xl = xl.min(x);
                xr = xr.max(x);
            }
        }
        if !(xl <= xr) {
            continue;
        }
        let x0 = (xl - PAD - 0.5).ceil().max(0.0);
        let x1 = (xr + PAD - 0.5).floor().min(width as f64 - 1.0);
        if x0 > x1 {
            continue;
        }
        for x in x0 as u32..=x1 as u32 {
            visit(x, y);
        }
    }
}
