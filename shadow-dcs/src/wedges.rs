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

use crate::centred::{CentredPlane, FastWeight};
use crate::edges::SceneEdge;
use crate::lanes::{TILE_W, TileLanes, band_lanes, lanes_of, span_mask};
use crate::light_shape::LightShape;

/// One (pixel, silhouette edge) pair: the edge and its weight `k_e(p)`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pair {
    /// Index into the silhouette list (of scene edge indices), which keeps the edges a frame
    /// touches together.
    pub edge: u32,
    /// `k_e(p)`: positive for the outer part of the wedge, negative for the inner part.
    pub k: i32,
}

/// The (pixel, edge, weight) pairs of a band of rows, grouped by pixel in edge order (CSR).
#[derive(Debug, Default)]
pub(crate) struct WedgePairs {
    /// First pixel of the band.
    pub first: usize,
    /// `start[i]..start[i + 1]` indexes the entries of band pixel `i`.
    pub start: Vec<u32>,
    /// The pairs, by pixel.
    pub entries: Vec<Pair>,
    /// Pixels scanned inside wedge hulls (before the exact test).
    pub scanned: u64,
}

impl WedgePairs {
    /// The entries of pixel `i` (image index, inside the band).
    pub fn of(&self, i: usize) -> &[Pair] {
        let j = i - self.first;
        &self.entries[self.start[j] as usize..self.start[j + 1] as usize]
    }
}

/// The screen region of one wedge.
#[derive(Debug, Clone)]
pub(crate) struct Region {
    edge: u32,
    /// The edge's position in the silhouette list.
    sil: u32,
    /// Convex polygon in pixel units; `None` scans the whole image.
    poly: Option<Vec<DVec2>>,
    rows: (u32, u32),
    /// Half-spaces holding the wedge ([`wedge_planes`]) around the light centre, in single
    /// precision (their slack covers its rounding).
    centred_planes: Vec<CentredPlane>,
    /// The planes of the edge's two faces, oriented by the edge, when the edge's weight can
    /// only be non-zero where it is a silhouette of the view sample ([`fold_planes`]), around
    /// the light centre.
    centred_fold: Option<(CentredPlane, CentredPlane)>,
    /// The weight from plane signs, for edges with one or two faces.
    weight: Option<FastWeight>,
}

/// A half-space `n . x + d >= 0` (`n` unit).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Plane {
    n: DVec3,
    d: f64,
}

impl Plane {
    #[inline]
    fn eval(&self, x: DVec3) -> f64 {
        self.n.dot(x) + self.d
    }
    /// The plane around the light centre `c`, in single precision.
    fn centred(&self, c: DVec3) -> CentredPlane {
        CentredPlane::new(self.n, self.d, c)
    }

    /// The largest value over a box (its corner furthest along `n`).
    #[inline]
    fn max_over(&self, lo: DVec3, hi: DVec3) -> f64 {
        let x = DVec3::new(
            if self.n.x > 0.0 { hi.x } else { lo.x },
            if self.n.y > 0.0 { hi.y } else { lo.y },
            if self.n.z > 0.0 { hi.z } else { lo.z },
        );
        self.eval(x)
    }
}

/// Half-spaces that hold the wedge of edge `e` (AAM03's wedge planes, made conservative for a
/// segment and a convex light with hull points `hull` around centre `c`):
/// * the two planes through the edge's line that support the light: every point
///   `x + t (x - y)` lies on the side away from the light (`n . (x - a) = 0` on the line, and
///   `n . (y - a) <= 0` for every light point);
/// * a side plane at each end point `v` with normal `n`, `n . (w - v) >= 0` toward the other end
///   `w` and `n . (y - v) <= 0` for every light point, which holds the whole wedge by the same
///   argument (kept only when such an `n` is found by tilting the edge direction away from the
///   light).
///
/// A view sample outside any of them cannot see the edge over the light, so the exact weight
/// need not be computed.
pub(crate) fn wedge_planes(e: &SceneEdge, hull: &[DVec3], c: DVec3) -> Vec<Plane> {
    let mut planes = Vec::with_capacity(4);
    let ab = e.b - e.a;
    let scale = ab.length() + hull.iter().map(|l| (*l - e.a).length()).fold(0.0, f64::max);
    let eps = 1e-9 * scale;
    let plane = |n: DVec3, at: DVec3| -> Option<Plane> {
        let len = n.length();
        (len > 0.0 && len.is_finite()).then(|| {
            let n = n / len;
            Plane {
                n,
                d: -n.dot(at) + 1e-6 * scale,
            }
        })
    };
    for l in hull {
        let n = ab.cross(*l - e.a);
        let len = n.length();
        if !(len > eps * scale) {
            continue;
        }
        let sides = hull.iter().map(|q| n.dot(*q - e.a) / len);
        let (lo, hi) = sides.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        if hi <= eps {
            planes.extend(plane(n, e.a));
        } else if lo >= -eps {
            planes.extend(plane(-n, e.a));
        }
    }
    // Both tangent planes are found once per supporting vertex; keep distinct ones.
    planes.dedup_by(|x, y| (x.n - y.n).length_squared() < 1e-18);
    for (v, w) in [(e.a, e.b), (e.b, e.a)] {
        let d = w - v;
        let u = c - v;
        let uu = u.length_squared();
        if !(uu > 0.0) {
            continue;
        }
        let perp = d - u * (d.dot(u) / uu);
        let mut lambda = 0.0f64;
        let mut ok = true;
        for l in hull {
            let den = u.dot(*l - v);
            if !(den > 0.0) {
                ok = false;
                break;
            }
            lambda = lambda.max(perp.dot(*l - v) / den);
        }
        let n = perp - u * lambda;
        if ok && n.dot(d) >= 0.0 {
            planes.extend(plane(n, v));
        }
    }
    planes
}

/// For a manifold edge whose faces weigh the same, `k_e(p)` is non-zero only where both faces
/// lie on one side of the plane through `p` and the edge (the edge is a silhouette of `p`):
/// with `P_i(p) = orient(w_i, a, b, p)` that is `P_1(p) P_2(p) > 0`. Two plane evaluations then
/// replace the full weight where the edge is not a silhouette of the pixel. Both planes carry
/// a small slack so that the prefilter never rejects a tie the exact weight would keep.
pub(crate) fn fold_planes(e: &SceneEdge) -> Option<(Plane, Plane)> {
    if e.always || e.faces.len() != 2 {
        return None;
    }
    let plane = |w: DVec3| -> Option<Plane> {
        let n = (e.a - w).cross(e.b - w);
        let len = n.length();
        (len > 0.0 && len.is_finite()).then(|| {
            let n = n / len;
            Plane { n, d: -n.dot(w) }
        })
    };
    let (p1, p2) = (plane(e.faces[0].third)?, plane(e.faces[1].third)?);
    Some((p1, p2))
}

/// Slack of the fold prefilter (distance), relative to the scene's extent.
const FOLD_SLACK: f64 = 1e-6;

/// Whether a box may hold a view sample of which the edge is a silhouette.
#[inline]
fn fold_possible_in(f: &(CentredPlane, CentredPlane), lo: Vec3, hi: Vec3, slack: f32) -> bool {
    let (max1, max2) = (f.0.max_over(lo, hi), f.1.max_over(lo, hi));
    let (min1, min2) = (f.0.min_over(lo, hi), f.1.min_over(lo, hi));
    (max1 > -slack && max2 > -slack) || (min1 < slack && min2 < slack)
}

/// Tiles per group: a group's box is tested before its tiles'.
const GROUP: usize = 8;

/// The union of tile boxes.
fn union_boxes(boxes: &[TileBox]) -> TileBox {
    boxes.iter().flatten().fold(None, |acc, (lo, hi)| {
        Some(match acc {
            Some((a, b)) => (lo.min(a), hi.max(b)),
            None => (*lo, *hi),
        })
    })
}

/// `None` for a tile with no active view sample; light-centred coordinates.
pub(crate) type TileBox = Option<(Vec3, Vec3)>;

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
        .enumerate()
        .filter_map(|(si, &ei)| {
            let e = &edges[ei as usize];
            let planes = wedge_planes(e, &hull, c);
            let fold = fold_planes(e);
            if planes.iter().any(|p| p.max_over(lo, hi) < 0.0) {
                return None;
            }
            let (poly, rows) = match screen_region(e, &hull, c, light.radius as f64, lo, hi, view) {
                None => (None, (0, view.height - 1)),
                Some(poly) => {
                    let rows = polygon_rows(&poly, view.height)?;
                    (Some(poly), rows)
                }
            };
            Some(Region {
                edge: ei,
                sil: si as u32,
                poly,
                rows,
                centred_planes: planes.iter().map(|p| p.centred(c)).collect(),
                centred_fold: fold.map(|(a, b)| (a.centred(c), b.centred(c))),
                weight: FastWeight::new(e, c),
            })
        })
        .collect();
    let unbounded = regions.iter().filter(|r| r.poly.is_none()).count() as u64;
    (regions, unbounded)
}

/// The rows of every region, compactly, so that a band finds its regions without touching the
/// others.
pub(crate) fn region_rows(regions: &[Region]) -> Vec<(u32, u32)> {
    regions.iter().map(|r| r.rows).collect()
}

/// The pairs of rows `rows` (a band): every region overlapping the band is scanned there (its
/// screen polygon's column range over the band's rows, tile by tile, skipping groups of tiles
/// whose view samples' box lies outside the wedge's planes or where the edge cannot be a
/// silhouette, and tiles where it cannot be one), and
/// each active pixel with a non-zero weight `k_e(p)` is kept. A tile's planes and weights are
/// evaluated on all its view samples at once ([`crate::lanes`]); lanes whose weight signs are
/// uncertain take the exact `SceneEdge::sweep_weight`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn band_pairs(
    edges: &[SceneEdge],
    regions: &[Region],
    all_rows: &[(u32, u32)],
    c: DVec3,
    view: &RasterView,
    rows: (u32, u32),
    origins: &[Vec3],
    centred: &[Vec3],
    active: &[bool],
    scale: f64,
    out: &mut WedgePairs,
    found: &mut Vec<(u32, Pair)>,
) {
    let w = view.width as usize;
    let first = rows.0 as usize * w;
    let n = (rows.1 - rows.0 + 1) as usize * w;
    found.clear();
    out.first = first;
    out.scanned = 0;
    out.entries.clear();
    out.start.clear();
    out.start.resize(n + 1, 0);
    let mut scanned = 0u64;
    let lanes = band_lanes(view.width, rows, centred, active);
    let tiles: Vec<TileBox> = lanes.iter().map(TileLanes::bounds).collect();
    let groups: Vec<TileBox> = tiles.chunks(GROUP).map(union_boxes).collect();
    let band_box = union_boxes(&groups);
    let slack = (FOLD_SLACK * scale) as f32;
    let Some((band_lo, band_hi)) = band_box else {
        return;
    };
    let no_silhouette = |r: &Region, lo: Vec3, hi: Vec3| -> bool {
        r.centred_fold
            .as_ref()
            .is_some_and(|f| !fold_possible_in(f, lo, hi, slack))
    };
    let rejects = |r: &Region, lo: Vec3, hi: Vec3| -> bool {
        r.centred_planes.iter().any(|p| p.max_over(lo, hi) < 0.0) || no_silhouette(r, lo, hi)
    };
    for (ri, _) in all_rows
        .iter()
        .enumerate()
        .filter(|(_, r)| r.1 >= rows.0 && r.0 <= rows.1)
    {
        let r = &regions[ri];
        if rejects(r, band_lo, band_hi) {
            continue;
        }
        let (y0, y1) = (rows.0.max(r.rows.0), rows.1.min(r.rows.1));
        let span = match &r.poly {
            Some(poly) => band_span(poly, y0, y1, view.width),
            None => Some((0, view.width - 1)),
        };
        let Some((xmin, xmax)) = span else {
            continue;
        };
        let e = &edges[r.edge as usize];
        let mut t = xmin / TILE_W;
        // The group whose box passed, tested once for all its tiles.
        let mut passed = usize::MAX;
        while t <= xmax / TILE_W {
            let g = t as usize / GROUP;
            if g != passed {
                if groups[g].is_none_or(|(lo, hi)| rejects(r, lo, hi)) {
                    t = (g as u32 + 1) * GROUP as u32;
                    continue;
                }
                passed = g;
            }
            let tc = t;
            t += 1;
            let Some((lo, hi)) = tiles[tc as usize] else {
                continue;
            };
            // The tile's box against the fold planes only: the wedge planes are cheaper on
            // the lanes themselves.
            if no_silhouette(r, lo, hi) {
                continue;
            }
            let tile = &lanes[tc as usize];
            let x0 = tc * TILE_W;
            let span = span_mask(
                xmin.max(x0) - x0,
                xmax.min(x0 + TILE_W - 1) - x0,
                y0 - rows.0,
                y1 - rows.0,
            );
            scanned += u64::from(span.count_ones());
            let inside = span & tile.active & CentredPlane::inside_all(&r.centred_planes, tile);
            if inside == 0 {
                continue;
            }
            let fast = r.weight.as_ref().and_then(|f| f.weight_lanes(tile));
            for j in lanes_of(inside) {
                let i =
                    (rows.0 + j as u32 / TILE_W) as usize * w + (x0 + j as u32 % TILE_W) as usize;
                let k = match &fast {
                    Some(f) if f.certain >> j & 1 == 1 => i64::from(f.k[j]),
                    _ => match e.sweep_weight(origins[i].as_dvec3(), c, false) {
                        Some(k) => k,
                        None => continue,
                    },
                };
                if k != 0 {
                    let k = k.clamp(i32::MIN as i64, i32::MAX as i64) as i32;
                    found.push(((i - first) as u32, Pair { edge: r.sil, k }));
                }
            }
        }
    }
    // Counting sort by pixel, stable: each pixel's pairs stay in edge order. `start[j + 1]`
    // first counts pixel `j`'s pairs; after the running sum, `start[j]` is pixel `j`'s fill
    // position, which ends at the start of pixel `j + 1`.
    let start = &mut out.start;
    for (j, _) in found.iter() {
        start[*j as usize + 1] += 1;
    }
    for j in 0..n {
        start[j + 1] += start[j];
    }
    out.entries.resize(found.len(), Pair { edge: 0, k: 0 });
    for (j, pair) in found.iter() {
        let slot = &mut start[*j as usize];
        out.entries[*slot as usize] = *pair;
        *slot += 1;
    }
    // Each `start[j]` now holds the start of pixel `j + 1`: shift back.
    start.copy_within(0..n, 1);
    start[0] = 0;
    out.scanned = scanned;
}

/// The columns whose pixel centres a convex polygon may cover on rows `y0..=y1` (the union of
/// the rows' spans, up to the polygon's slope across the band), `None` when none.
fn band_span(poly: &[DVec2], y0: u32, y1: u32, width: u32) -> Option<(u32, u32)> {
    let n = poly.len();
    if n == 0 {
        return None;
    }
    let (ylo, yhi) = (y0 as f64 + 0.5 - PAD, y1 as f64 + 0.5 + PAD);
    let (mut xl, mut xr) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut prev = poly[n - 1];
    for &b in poly {
        let a = std::mem::replace(&mut prev, b);
        let (top, bottom) = (a.y.min(b.y), a.y.max(b.y));
        if bottom < ylo || top > yhi {
            continue;
        }
        // The part of the edge inside the slab.
        let dy = b.y - a.y;
        let (t0, t1) = if dy.abs() < 1e-12 {
            (0.0, 1.0)
        } else {
            let (s0, s1) = ((ylo - a.y) / dy, (yhi - a.y) / dy);
            (s0.min(s1).max(0.0), s0.max(s1).min(1.0))
        };
        for t in [t0, t1] {
            let x = a.x + (b.x - a.x) * t;
            xl = xl.min(x);
            xr = xr.max(x);
        }
    }
    if n < 3 && !(xl <= xr) {
        for p in poly {
            xl = xl.min(p.x);
            xr = xr.max(p.x);
        }
    }
    if !(xl <= xr) {
        return None;
    }
    let x0 = (xl - PAD - 0.5).ceil().max(0.0);
    let x1 = (xr + PAD - 0.5).floor().min(width as f64 - 1.0);
    (x0 <= x1).then_some((x0 as u32, x1 as u32))
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
    // Only the part inside the view samples' box can hold one: clip the hull to it.
    let pad = (hi - lo).length() * 1e-6 + 1e-12;
    let dir = (e.a + e.b) * 0.5 - c;
    let pts = clip_hull_to_box(pts, dir, lo - DVec3::splat(pad), hi + DVec3::splat(pad));
    if pts.is_empty() {
        return Some(Vec::new());
    }
    let to_view = view.view_from_world;
    let m = glam::Mat4::from(to_view).as_dmat4();
    let vp: Vec<DVec3> = pts.iter().map(|p| m.transform_point3(*p)).collect();
    let (l, r, b, tp, near, persp) = view.extents();
    let near = near as f64;
    // Clip the point cloud's hull against depth >= near: points in front, plus the crossings
    // of every segment from a point in front to a point behind.
    let depth = |q: &DVec3| -q.z;
    let kept: Vec<DVec3> = if vp.iter().all(|q| depth(q) >= near) {
        vp
    } else {
        let mut kept: Vec<DVec3> = vp.iter().copied().filter(|q| depth(q) >= near).collect();
        let behind: Vec<DVec3> = vp.iter().copied().filter(|q| depth(q) < near).collect();
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
        kept
    };
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

/// Points whose convex hull is the convex hull of `pts` clipped by the box face that the
/// direction `dir` leaves through (the one along its largest component): the points inside the
/// face and the crossings of every segment from an inside point to an outside one (every vertex
/// of a clipped polytope is an inside vertex or lies on an edge that crosses the face). One face
/// keeps the point count small; the other faces would cut less of a wedge.
fn clip_hull_to_box(pts: Vec<DVec3>, dir: DVec3, lo: DVec3, hi: DVec3) -> Vec<DVec3> {
    let axis = dir.abs().max_position();
    let below = dir[axis] > 0.0;
    let bound = if below { hi[axis] } else { lo[axis] };
    let inside = |p: &DVec3| {
        if below {
            p[axis] <= bound
        } else {
            p[axis] >= bound
        }
    };
    let split = {
        let mut pts = pts;
        // Inside points first, in their order; the rest after them.
        pts.sort_by_key(|p| !inside(p));
        pts
    };
    let n_in = split.iter().take_while(|p| inside(p)).count();
    if n_in == split.len() {
        return split;
    }
    let (ins, outs) = split.split_at(n_in);
    let mut next = Vec::with_capacity(n_in * (1 + outs.len()));
    next.extend_from_slice(ins);
    for a in ins {
        for b in outs {
            let t = (bound - a[axis]) / (b[axis] - a[axis]);
            let mut x = *a + (*b - *a) * t;
            x[axis] = bound;
            next.push(x);
        }
    }
    next
}

/// Andrew's monotone chain; counter-clockwise in a y-up frame (orientation is irrelevant to the
/// scan).
pub(crate) fn convex_hull(mut p: Vec<DVec2>) -> Vec<DVec2> {
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<DVec2> = Vec::with_capacity(p.len() * 2);
    // Lower chain left to right, then upper chain right to left.
    let chain = |hull: &mut Vec<DVec2>, q: DVec2, start: usize| {
        while hull.len() >= start + 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
        {
            hull.pop();
        }
        hull.push(q);
    };
    for &q in &p {
        chain(&mut hull, q, 0);
    }
    hull.pop();
    let start = hull.len();
    for &q in p.iter().rev() {
        chain(&mut hull, q, start);
    }
    hull.pop();
    hull
}

/// Slack in pixels around wedge polygons.
const PAD: f64 = 0.01;
