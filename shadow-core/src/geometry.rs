//! Small geometric helpers shared by every crate: axis-aligned boxes, triangle measures and the
//! planar convex hull.

use glam::{DVec2, DVec3, Vec3};
use serde::{Deserialize, Serialize};

/// An axis-aligned bounding box. [`Aabb::empty`] is the identity of [`Aabb::union`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box: `min = +inf`, `max = -inf`.
    pub fn empty() -> Self {
        Self {
            min: Vec3::splat(f32::INFINITY),
            max: Vec3::splat(f32::NEG_INFINITY),
        }
    }

    /// The smallest box holding every point (empty for no points).
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a Vec3>) -> Self {
        points.into_iter().fold(Self::empty(), |b, p| b.grow(*p))
    }

    /// This box grown to hold `p`.
    #[must_use]
    pub fn grow(self, p: Vec3) -> Self {
        Self {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The smallest box holding both boxes.
    #[must_use]
    pub fn union(self, other: Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// True when the box holds no point.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// Centre of the box.
    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    /// Size along each axis (zero for an empty box).
    pub fn extent(&self) -> Vec3 {
        if self.is_empty() {
            Vec3::ZERO
        } else {
            self.max - self.min
        }
    }

    /// Length of the diagonal (zero for an empty box).
    pub fn diagonal(&self) -> f32 {
        self.extent().length()
    }

    /// The eight corners.
    pub fn corners(&self) -> [Vec3; 8] {
        let (a, b) = (self.min, self.max);
        [
            Vec3::new(a.x, a.y, a.z),
            Vec3::new(b.x, a.y, a.z),
            Vec3::new(a.x, b.y, a.z),
            Vec3::new(b.x, b.y, a.z),
            Vec3::new(a.x, a.y, b.z),
            Vec3::new(b.x, a.y, b.z),
            Vec3::new(a.x, b.y, b.z),
            Vec3::new(b.x, b.y, b.z),
        ]
    }
}

/// Twice the area vector of a triangle, computed in f64 so that slivers keep their true size.
pub fn triangle_cross_f64(a: Vec3, b: Vec3, c: Vec3) -> DVec3 {
    let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
    (b - a).cross(c - a)
}

/// Area of a triangle (f64 internally).
pub fn triangle_area(a: Vec3, b: Vec3, c: Vec3) -> f32 {
    (0.5 * triangle_cross_f64(a, b, c).length()) as f32
}

/// Unit normal of a triangle following its winding (counter-clockwise = front), or `None` when
/// the triangle has no area.
pub fn triangle_normal(a: Vec3, b: Vec3, c: Vec3) -> Option<Vec3> {
    let n = triangle_cross_f64(a, b, c);
    let len = n.length();
    (len > 0.0 && len.is_finite()).then(|| (n / len).as_vec3())
}

/// An orthonormal basis `(t, b)` completing the unit vector `n` (Duff et al. 2017, "Building an
/// orthonormal basis, revisited"), continuous except at `n.z = -1` where it stays valid.
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// Area of a simple polygon given in 2D (shoelace, signed: positive when counter-clockwise).
pub fn polygon_signed_area(points: &[glam::Vec2]) -> f64 {
    let n = points.len();
    let mut s = 0.0f64;
    for i in 0..n {
        let p = points[i].as_dvec2();
        let q = points[(i + 1) % n].as_dvec2();
        s += p.x * q.y - q.x * p.y;
    }
    0.5 * s
}

/// The convex hull of planar points by Andrew's monotone chain, counter-clockwise in a y-up
/// frame, duplicate and collinear points dropped; fewer than three distinct points come back
/// as they are (sorted). DCS's light outline and AFSM's influence regions both take it.
pub fn convex_hull(mut p: Vec<DVec2>) -> Vec<DVec2> {
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

/// Moller-Trumbore in f64: does the ray `o + t d`, `0 < t < t_max`, hit the triangle `a b c`?
/// What the parity tests of closed meshes take (DCS's one-sided meshes, AFSM's eye inside a
/// closed mesh).
pub fn ray_hits_triangle(o: DVec3, d: DVec3, a: DVec3, b: DVec3, c: DVec3, t_max: f64) -> bool {
    ray_triangle_t(o, d, a, b, c, t_max).is_some()
}

/// [`ray_hits_triangle`]'s hit parameter `t`, when it hits.
pub fn ray_triangle_t(o: DVec3, d: DVec3, a: DVec3, b: DVec3, c: DVec3, t_max: f64) -> Option<f64> {
    let e1 = b - a;
    let e2 = c - a;
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let tv = o - a;
    let u = tv.dot(pv) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qv = tv.cross(e1);
    let v = d.dot(qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(qv) * inv;
    (t > 0.0 && t < t_max).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_orthonormal() {
        for n in [
            Vec3::X,
            Vec3::Y,
            Vec3::Z,
            -Vec3::Z,
            Vec3::new(1.0, 2.0, -3.0).normalize(),
        ] {
            let (t, b) = orthonormal_basis(n);
            assert!(t.dot(n).abs() < 1e-6 && b.dot(n).abs() < 1e-6 && t.dot(b).abs() < 1e-6);
            assert!((t.length() - 1.0).abs() < 1e-6 && (b.length() - 1.0).abs() < 1e-6);
            assert!(t.cross(b).dot(n) > 0.999);
        }
    }

    #[test]
    fn aabb_union_and_empty() {
        let e = Aabb::empty();
        assert!(e.is_empty());
        let b = Aabb::from_points(&[Vec3::ZERO, Vec3::ONE]);
        assert_eq!(e.union(b), b);
        assert_eq!(b.extent(), Vec3::ONE);
    }
}
