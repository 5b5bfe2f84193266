//! Per-triangle set-up: near-plane clipping in view space, projection to the screen and the
//! edge functions with the top-left rule.

use glam::{DVec2, Vec3};

use super::RasterView;

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
    pub xmin: u32,
    pub xmax: u32,
    pub ymin: u32,
    pub ymax: u32,
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

    /// True when the centre of pixel `(x, y)` is covered (top-left rule).
    pub fn covers(&self, x: u32, y: u32) -> bool {
        self.weights_at(x, y).is_some()
    }

    /// The columns of row `y` that may be covered: the interval where every edge function is
    /// non-negative at the row's centre line, widened by a pixel on each side so that the exact
    /// test ([`ScreenTriangle::covers`]) decides at the ends. `None` when the row misses.
    pub fn row_candidates(&self, y: u32) -> Option<(u32, u32)> {
        let yc = y as f64 + 0.5;
        let (mut lo, mut hi) = (self.xmin as f64, self.xmax as f64 + 1.0);
        for i in 0..3 {
            let (a, b) = (self.p[i], self.p[(i + 1) % 3]);
            // edge(a, b, (x, yc)) = (b.x - a.x)(yc - a.y) - (b.y - a.y)(x - a.x) >= 0.
            let k = -(b.y - a.y);
            let c0 = (b.x - a.x) * (yc - a.y) + (b.y - a.y) * a.x;
            if k == 0.0 {
                if c0 < 0.0 {
                    return None;
                }
                continue;
            }
            let x = -c0 / k;
            if k > 0.0 {
                lo = lo.max(x - 0.5);
            } else {
                hi = hi.min(x - 0.5);
            }
        }
        let x0 = (lo.floor() - 1.0).max(self.xmin as f64);
        let x1 = (hi.ceil() + 1.0).min(self.xmax as f64);
        (x0 <= x1).then_some((x0 as u32, x1 as u32))
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

/// Clips a view-space triangle against the near plane and returns up to two screen triangles.
pub(super) fn setup_triangle(v: [Vec3; 3], view: &RasterView) -> Vec<ScreenTriangle> {
    let (l, r, b, t, near, persp) = view.extents();
    // Depth d = -z; keep d >= near (Sutherland-Hodgman on one plane), in f64.
    let pts: Vec<glam::DVec3> = v.iter().map(|p| p.as_dvec3()).collect();
    let near = near as f64;
    let mut poly: Vec<glam::DVec3> = Vec::with_capacity(4);
    for i in 0..3 {
        let (a, c) = (pts[i], pts[(i + 1) % 3]);
        let (da, dc) = (-a.z - near, -c.z - near);
        if da >= 0.0 {
            poly.push(a);
        }
        if (da >= 0.0) != (dc >= 0.0) {
            let s = da / (da - dc);
            let mut q = a + (c - a) * s;
            q.z = -near; // exactly on the plane
            poly.push(q);
        }
    }
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
    let mut out = Vec::with_capacity(2);
    for i in 1..projected.len() - 1 {
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
        let lo = p[0].min(p[1]).min(p[2]);
        let hi = p[0].max(p[1]).max(p[2]);
        // Pixel centres x + 0.5 inside [lo, hi].
        let xmin = (lo.x - 0.5).ceil().max(0.0);
        let ymin = (lo.y - 0.5).ceil().max(0.0);
        let xmax = (hi.x - 0.5).floor().min(w - 1.0);
        let ymax = (hi.y - 0.5).floor().min(h - 1.0);
        if xmin > xmax || ymin > ymax {
            continue;
        }
        let top_left = std::array::from_fn(|i| {
            let (a, c) = (p[i], p[(i + 1) % 3]);
            let (dx, dy) = (c.x - a.x, c.y - a.y);
            (dy == 0.0 && dx > 0.0) || dy < 0.0
        });
        out.push(ScreenTriangle {
            p,
            z: [tri[0].1, tri[1].1, tri[2].1],
            perspective: persp,
            area,
            top_left,
            xmin: xmin as u32,
            xmax: xmax as u32,
            ymin: ymin as u32,
            ymax: ymax as u32,
        });
    }
    out
}
