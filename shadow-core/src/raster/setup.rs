//! Per-triangle set-up: near-plane clipping in view space, projection to the screen and the
//! edge functions with the top-left rule.

use glam::{DVec2, Vec3};

use super::RasterView;
use crate::rounding::{ceil_f64, floor_f64};

/// A screen-space triangle ready for scan conversion.
#[derive(Debug, Clone)]
pub(super) struct ScreenTriangle {
    /// Screen positions (pixel units, y down).
    p: [DVec2; 3],
    /// Per-vertex depth term: `1/d` for perspective, `d` for orthographic.
    z: [f64; 3],
    perspective: bool,
    /// Twice the signed area (> 0 after orientation).
    area: f64,
    /// Top-left flags per edge `i -> i+1`.
    top_left: [bool; 3],
    /// Per edge `i -> i+1`: where its line crosses a row's centre line `yc`,
    /// `x = cross[i].0 + cross[i].1 yc`, and whether the inside lies right of it (`1.0`), left
    /// of it (`-1.0`) or the edge is horizontal (`0.0`, inside when `horizontal_inside`).
    cross: [(f64, f64, f64); 3],
    pub xmin: u32,
    pub xmax: u32,
    pub ymin: u32,
    pub ymax: u32,
}

/// `a.max(b)` as one compare and select: `f64::max`'s NaN handling costs three more
/// instructions on the baseline x86-64, in code run for every row. The same value whenever `a`
/// is not NaN (a NaN `b` leaves `a`, as `f64::max` does); a zero's sign may differ, which no
/// rounding or comparison here sees.
#[inline(always)]
fn max_of(a: f64, b: f64) -> f64 {
    if b > a { b } else { a }
}

/// `a.min(b)` as one compare and select (see [`max_of`]).
#[inline(always)]
fn min_of(a: f64, b: f64) -> f64 {
    if b < a { b } else { a }
}

fn edge(a: DVec2, b: DVec2, p: DVec2) -> f64 {
    (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)
}

impl ScreenTriangle {
    /// Edge-function weights at the centre of pixel `(x, y)` when it is covered (top-left rule).
    fn weights_at(&self, x: u32, y: u32) -> Option<[f64; 3]> {
        let c = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
        let mut w = [0.0; 3];
        for i in 0..3 {
            let (a, b) = (self.p[i], self.p[(i + 1) % 3]);
            let e = edge(a, b, c);
            if e < 0.0 || (e == 0.0 && !self.top_left[i]) {
                return None;
            }
            // Edge i -> i+1 weighs the opposite vertex i+2.
            w[(i + 2) % 3] = e;
        }
        Some(w)
    }

    /// The depth term's plane over the screen, relative to vertex 0: `(dz/dx, dz/dy)`, so
    /// that the term at `c` is `z[0] + g.x (c.x - p[0].x) + g.y (c.y - p[0].y)`. The same
    /// plane the barycentric weights interpolate, rounded differently in the last f64 bits
    /// (the depth is then rounded to f32); relative to a vertex, so the terms stay of the
    /// size of the triangle's own depth range.
    pub fn depth_gradient(&self) -> DVec2 {
        let (p, z) = (&self.p, &self.z);
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let (dz1, dz2) = (z[1] - z[0], z[2] - z[0]);
        DVec2::new(dz1 * e2.y - dz2 * e1.y, dz2 * e1.x - dz1 * e2.x) / self.area
    }

    /// The depth of a pixel known to be covered (one of a [`ConvexRows::row_span`] run) from
    /// the plane `g` ([`ScreenTriangle::depth_gradient`]): one division where
    /// [`ScreenTriangle::depth_at_center`] takes four and three edge functions.
    #[inline]
    pub fn depth_on_plane(&self, g: DVec2, x: u32, y: u32) -> Option<f32> {
        let c = DVec2::new(x as f64 + 0.5, y as f64 + 0.5) - self.p[0];
        let zi = self.z[0] + g.x * c.x + g.y * c.y;
        let d = if self.perspective { 1.0 / zi } else { zi };
        let d = d as f32;
        d.is_finite().then_some(d)
    }

    /// Linear depth at the centre of pixel `(x, y)` when covered.
    pub fn depth_at_center(&self, x: u32, y: u32) -> Option<f32> {
        let w = self.weights_at(x, y)?;
        let (b0, b1, b2) = (w[0] / self.area, w[1] / self.area, w[2] / self.area);
        let zi = b0 * self.z[0] + b1 * self.z[1] + b2 * self.z[2];
        let d = if self.perspective { 1.0 / zi } else { zi };
        let d = d as f32;
        d.is_finite().then_some(d)
    }
}

/// The [`ConvexRows`] accessors of a set-up with fields `p`, `top_left`, `cross`, `xmin` and
/// `xmax`.
macro_rules! convex_fields {
    () => {
        fn vertices(&self) -> &[DVec2] {
            &self.p
        }
        fn top_left(&self) -> &[bool] {
            &self.top_left
        }
        fn crossings(&self) -> &[(f64, f64, f64)] {
            &self.cross
        }
        fn x_range(&self) -> (u32, u32) {
            (self.xmin, self.xmax)
        }
    };
}

impl ConvexRows for ScreenTriangle {
    convex_fields!();
    /// The pixels that have a depth ([`ScreenTriangle::depth_at_center`]): the same rule as
    /// the default, from the same weights.
    fn covers(&self, x: u32, y: u32) -> bool {
        self.weights_at(x, y).is_some()
    }
}

/// A convex polygon on the screen with positive area (the same edge functions, top-left rule
/// and row crossings as a triangle): coverage without depth, for faces scan-converted whole (a
/// face split into triangles pays each row once per triangle).
#[derive(Debug, Clone)]
pub(super) struct ScreenPolygon {
    p: Vec<DVec2>,
    top_left: Vec<bool>,
    cross: Vec<(f64, f64, f64)>,
    pub xmin: u32,
    pub xmax: u32,
    pub ymin: u32,
    pub ymax: u32,
}

impl ConvexRows for ScreenPolygon {
    convex_fields!();
}

/// Scan conversion by rows of a convex screen polygon (a triangle or a whole face): its
/// vertices in order with positive area, each edge's top-left flag and where its line crosses
/// a row's centre line.
pub(super) trait ConvexRows {
    /// The vertices, in order with positive area.
    fn vertices(&self) -> &[DVec2];
    /// Per edge `i -> i+1`: whether it is a top or left edge.
    fn top_left(&self) -> &[bool];
    /// Per edge `i -> i+1`: where its line crosses a row's centre line `yc`,
    /// `x = cross[i].0 + cross[i].1 yc`, and whether the inside lies right of it (`1.0`), left
    /// of it (`-1.0`) or the edge is horizontal (`0.0`).
    fn crossings(&self) -> &[(f64, f64, f64)];
    /// The first and last columns that may be covered.
    fn x_range(&self) -> (u32, u32);

    /// True when the centre of pixel `(x, y)` is covered (top-left rule).
    fn covers(&self, x: u32, y: u32) -> bool {
        let c = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
        let (p, top_left) = (self.vertices(), self.top_left());
        (0..p.len()).all(|i| {
            let e = edge(p[i], p[(i + 1) % p.len()], c);
            e > 0.0 || (e == 0.0 && top_left[i])
        })
    }

    /// The columns of row `y` that may be covered: the interval where every edge function is
    /// non-negative at the row's centre line, widened by a pixel on each side so that the exact
    /// test ([`ConvexRows::covers`]) decides at the ends. `None` when the row misses.
    fn row_candidates(&self, y: u32) -> Option<(u32, u32)> {
        let yc = y as f64 + 0.5;
        let (xmin, xmax) = self.x_range();
        let p = self.vertices();
        let (mut lo, mut hi) = (xmin as f64, xmax as f64 + 1.0);
        for (i, &(x0, slope, side)) in self.crossings().iter().enumerate() {
            // edge(a, b, (x, yc)) = (b.x - a.x)(yc - a.y) - (b.y - a.y)(x - a.x) >= 0: right of
            // the crossing when b.y < a.y, left of it when b.y > a.y.
            if side == 0.0 {
                let (a, b) = (p[i], p[(i + 1) % p.len()]);
                if (b.x - a.x) * (yc - a.y) < 0.0 {
                    return None;
                }
                continue;
            }
            let x = x0 + slope * yc;
            if side > 0.0 {
                lo = max_of(lo, x - 0.5);
            } else {
                hi = min_of(hi, x - 0.5);
            }
        }
        let x0 = max_of(floor_f64(lo) - 1.0, xmin as f64);
        let x1 = min_of(ceil_f64(hi) + 1.0, xmax as f64);
        (x0 <= x1).then_some((x0 as u32, x1 as u32))
    }

    /// The covered pixels of row `y` as one run `x0..=x1` (`None` when none): exactly the pixels
    /// [`ConvexRows::covers`] accepts. The run's ends come from where the edges cross the
    /// row's centre line; an end within the rounding of that crossing (or any end, on a row
    /// that a horizontal edge or a nearly horizontal one makes delicate) is settled by the
    /// exact test.
    fn row_span(&self, y: u32) -> Option<(u32, u32)> {
        let yc = y as f64 + 0.5;
        let (xmin, xmax) = self.x_range();
        let p = self.vertices();
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        // Rounding of the crossings (a few units in the last place of their terms).
        let mut err = 0.0f64;
        for (i, &(x0, slope, side)) in self.crossings().iter().enumerate() {
            if side == 0.0 {
                let (a, b) = (p[i], p[(i + 1) % p.len()]);
                let c = (b.x - a.x) * (yc - a.y);
                if c < 0.0 {
                    return None;
                }
                if c == 0.0 {
                    return self.row_span_exact(y);
                }
                continue;
            }
            let x = x0 + slope * yc - 0.5;
            err = max_of(err, (x0.abs() + (slope * yc).abs() + 1.0) * 1e-14);
            if side > 0.0 {
                lo = max_of(lo, x);
            } else {
                hi = min_of(hi, x);
            }
        }
        let eps = max_of(err, 1e-9);
        if !(eps < 0.25) {
            return self.row_span_exact(y);
        }
        let a = max_of(ceil_f64(lo - eps), xmin as f64);
        let b = min_of(floor_f64(hi + eps), xmax as f64);
        if !(a <= b) {
            return None;
        }
        let (mut a, mut b) = (a as u32, b as u32);
        // Pixels left of `a` or right of `b` are surely outside; between `lo + eps` and
        // `hi - eps` surely inside.
        if (a as f64) < lo + eps && !self.covers(a, y) {
            a += 1;
        }
        if (b as f64) > hi - eps && b >= a && !self.covers(b, y) {
            if b == 0 {
                return None;
            }
            b -= 1;
        }
        (a <= b).then_some((a, b))
    }

    /// [`ConvexRows::row_span`] by the exact test from the widened candidates.
    fn row_span_exact(&self, y: u32) -> Option<(u32, u32)> {
        let (mut x0, mut x1) = self.row_candidates(y)?;
        while x0 <= x1 && !self.covers(x0, y) {
            x0 += 1;
        }
        while x1 > x0 && !self.covers(x1, y) {
            x1 -= 1;
        }
        (x0 <= x1 && self.covers(x1, y)).then_some((x0, x1))
    }
}

/// The part of the view-space convex polygon `v` in front of the near plane (Sutherland-Hodgman
/// on one plane, in f64), projected to the screen: each vertex's position and depth term
/// (`1/d` for perspective, `d` for orthographic). Empty when fewer than three vertices are
/// left or a projected value is not finite.
fn clip_and_project(v: &[Vec3], view: &RasterView) -> Vec<(DVec2, f64)> {
    let (l, r, b, t, near, persp) = view.extents();
    // Depth d = -z; keep d >= near.
    let pts: Vec<glam::DVec3> = v.iter().map(|p| p.as_dvec3()).collect();
    let near = near as f64;
    let mut poly: Vec<glam::DVec3> = Vec::with_capacity(pts.len() + 1);
    let depth = |a: glam::DVec3| -a.z - near;
    crate::clip::clip_polygon(
        &pts,
        &mut poly,
        |a| depth(a) >= 0.0,
        |a, c| {
            let (da, dc) = (depth(a), depth(c));
            let s = da / (da - dc);
            let mut q = a + (c - a) * s;
            q.z = -near; // exactly on the plane
            q
        },
    );
    if poly.len() < 3 {
        return Vec::new();
    }
    let (w, h) = (view.width as f64, view.height as f64);
    let (l, r, b, t) = (l as f64, r as f64, b as f64, t as f64);
    let project = |q: glam::DVec3| -> (DVec2, f64) {
        let d = -q.z;
        let (x, y) = if persp {
            (q.x / d, q.y / d)
        } else {
            (q.x, q.y)
        };
        (
            DVec2::new((x - l) / (r - l) * w, (t - y) / (t - b) * h),
            if persp { 1.0 / d } else { d },
        )
    };
    let projected: Vec<(DVec2, f64)> = poly.iter().map(|q| project(*q)).collect();
    if projected
        .iter()
        .any(|(p, z)| !p.is_finite() || !z.is_finite())
    {
        return Vec::new();
    }
    projected
}

/// The pixel bounds of the screen points `p` (pixel centres inside their box), `None` when no
/// pixel centre of the `view` lies inside: `(xmin, xmax, ymin, ymax)`.
fn pixel_bounds(p: &[DVec2], view: &RasterView) -> Option<(u32, u32, u32, u32)> {
    let (w, h) = (view.width as f64, view.height as f64);
    let lo = p.iter().fold(p[0], |m, q| m.min(*q));
    let hi = p.iter().fold(p[0], |m, q| m.max(*q));
    // Pixel centres x + 0.5 inside [lo, hi].
    let xmin = (lo.x - 0.5).ceil().max(0.0);
    let ymin = (lo.y - 0.5).ceil().max(0.0);
    let xmax = (hi.x - 0.5).floor().min(w - 1.0);
    let ymax = (hi.y - 0.5).floor().min(h - 1.0);
    (xmin <= xmax && ymin <= ymax).then_some((xmin as u32, xmax as u32, ymin as u32, ymax as u32))
}

/// The top-left flag and the row crossing ([`ConvexRows::crossings`]) of edge `a -> c`.
fn edge_rows(a: DVec2, c: DVec2) -> (bool, (f64, f64, f64)) {
    let (dx, dy) = (c.x - a.x, c.y - a.y);
    let top_left = (dy == 0.0 && dx > 0.0) || dy < 0.0;
    let cross = if dy == 0.0 {
        (0.0, 0.0, 0.0)
    } else {
        let slope = (c.x - a.x) / dy;
        (a.x - slope * a.y, slope, if dy < 0.0 { 1.0 } else { -1.0 })
    };
    (top_left, cross)
}

/// Clips a view-space triangle against the near plane and returns up to two screen triangles.
pub(super) fn setup_triangle(v: [Vec3; 3], view: &RasterView) -> Vec<ScreenTriangle> {
    let persp = view.extents().5;
    let projected = clip_and_project(&v, view);
    // Allocated at the first piece, for the pieces left: a triangle that reaches no pixel
    // centre (most of a dense mesh's, in a small view) allocates nothing, and the rasterizer
    // keeps each triangle's list until its chunk is scanned.
    let mut out = Vec::new();
    for i in 1..projected.len().saturating_sub(1) {
        let mut tri = [projected[0], projected[i], projected[i + 1]];
        let mut area = edge(tri[0].0, tri[1].0, tri[2].0);
        if area == 0.0 {
            continue;
        }
        if area < 0.0 {
            tri.swap(1, 2);
            area = -area;
        }
        let p = [tri[0].0, tri[1].0, tri[2].0];
        let Some((xmin, xmax, ymin, ymax)) = pixel_bounds(&p, view) else {
            continue;
        };
        let rows: [(bool, (f64, f64, f64)); 3] =
            std::array::from_fn(|i| edge_rows(p[i], p[(i + 1) % 3]));
        if out.is_empty() {
            out.reserve_exact(projected.len() - 1 - i);
        }
        out.push(ScreenTriangle {
            p,
            z: [tri[0].1, tri[1].1, tri[2].1],
            perspective: persp,
            area,
            top_left: rows.map(|r| r.0),
            cross: rows.map(|r| r.1),
            xmin,
            xmax,
            ymin,
            ymax,
        });
    }
    out
}

/// Clips a view-space convex planar polygon against the near plane and sets it up whole, its
/// vertices in order with positive area (the order of [`setup_triangle`]'s triangles for the
/// same outline). `None` when nothing of it is left or its screen area is zero.
pub(super) fn setup_polygon(v: &[Vec3], view: &RasterView) -> Option<ScreenPolygon> {
    let projected = clip_and_project(v, view);
    // Vertices within a millionth of a pixel of the previous one are dropped: clipping a
    // polygon at a box corner repeats a vertex (exactly, or to the last bits), and the edge
    // between the two copies has no direction, so its edge function excluded every pixel: a
    // DCS shadow-volume quad clipped at the corner of the box around the view counted nowhere
    // (the Cornell box's back-wall umbra came out lit).
    let mut p: Vec<DVec2> = Vec::with_capacity(projected.len());
    for q in &projected {
        if p.last()
            .is_none_or(|l: &DVec2| l.distance_squared(q.0) > 1e-12)
        {
            p.push(q.0);
        }
    }
    while p.len() > 1 && p[0].distance_squared(p[p.len() - 1]) <= 1e-12 {
        p.pop();
    }
    if p.len() < 3 {
        return None;
    }
    // Twice the signed area, from the fan of the first vertex (each term is a triangle's
    // `edge`).
    let area: f64 = (1..p.len() - 1).map(|i| edge(p[0], p[i], p[i + 1])).sum();
    if !(area != 0.0) {
        return None;
    }
    if area < 0.0 {
        // The first vertex stays first, as in a triangle whose last two are swapped.
        p[1..].reverse();
    }
    let (xmin, xmax, ymin, ymax) = pixel_bounds(&p, view)?;
    let (top_left, cross) = (0..p.len())
        .map(|i| edge_rows(p[i], p[(i + 1) % p.len()]))
        .unzip();
    Some(ScreenPolygon {
        p,
        top_left,
        cross,
        xmin,
        xmax,
        ymin,
        ymax,
    })
}
