//! The polygon clipper every technique uses: Sutherland-Hodgman (Sutherland and Hodgman 1974,
//! "Reentrant polygon clipping") against one half-space at a time. The rasterizer clips
//! triangles at the near plane, the irradiance integral clips lights by a receiver's planes
//! (`crate::irradiance`), DCS clips shadow-volume quads to a box and soft shadow mapping clips
//! the light's outline to texel rectangles and wedges. Each caller keeps its own inside test
//! and crossing point, since those fix its results to the bit (a strict or closed half-space,
//! a crossing snapped onto the plane or interpolated from a canonical end point); the walk
//! over the edges is this one.

use std::ops::{Add, Mul, Sub};

/// Clips the closed polygon `poly` by one half-space into `out` (cleared first): walking each
/// edge `a -> b`, `a` is kept when `inside(a)`, and where the edge crosses the boundary,
/// `crossing(a, b)` is added.
pub fn clip_polygon<V: Copy>(
    poly: &[V],
    out: &mut Vec<V>,
    inside: impl Fn(V) -> bool,
    crossing: impl Fn(V, V) -> V,
) {
    out.clear();
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        let a_in = inside(a);
        if a_in {
            out.push(a);
        }
        if a_in != inside(b) {
            out.push(crossing(a, b));
        }
    }
}

/// Which side of `side(x) = 0` a clip keeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Keep {
    /// `side(x) > 0`: points on the boundary are dropped.
    Positive,
    /// `side(x) >= 0`: points on the boundary are kept.
    NonNegative,
}

/// [`clip_polygon`] by the half-space where the linear function `side` is positive (or
/// non-negative), each crossing at `a + (b - a) * side(a) / (side(a) - side(b))`.
pub fn clip_by_side<V>(poly: &[V], out: &mut Vec<V>, side: impl Fn(V) -> f64, keep: Keep)
where
    V: Copy + Add<Output = V> + Sub<Output = V> + Mul<f64, Output = V>,
{
    let inside = |v: V| match keep {
        Keep::Positive => side(v) > 0.0,
        Keep::NonNegative => side(v) >= 0.0,
    };
    clip_polygon(poly, out, inside, |a, b| {
        let (sa, sb) = (side(a), side(b));
        a + (b - a) * (sa / (sa - sb))
    });
}

#[cfg(test)]
mod tests {
    use glam::{DVec2, DVec3};

    use super::*;

    fn area(p: &[DVec2]) -> f64 {
        let n = p.len();
        0.5 * (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum::<f64>()
    }

    #[test]
    fn a_square_cut_by_a_diagonal_half_plane_keeps_half_its_area() {
        let square = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ];
        let mut out = Vec::new();
        clip_by_side(&square, &mut out, |p| p.y - p.x, Keep::NonNegative);
        assert!((area(&out) - 0.5).abs() < 1e-15, "{out:?}");
        // The corners on the diagonal are kept by the closed half-plane, and the edges leaving
        // them cross it there again: Sutherland-Hodgman repeats boundary points (zero-length
        // edges that every caller's integral or rasterizer takes as nothing).
        assert!(out.iter().all(|p| p.y >= p.x));
        assert_eq!(out.len(), 5);
        clip_by_side(&square, &mut out, |p| p.x - 2.0, Keep::Positive);
        assert!(out.is_empty());
        clip_by_side(&square, &mut out, |p| p.x + 1.0, Keep::Positive);
        assert_eq!(out, square);
    }

    #[test]
    fn a_triangle_through_a_plane_keeps_the_part_in_front() {
        let tri = [
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        ];
        let mut out = Vec::new();
        clip_by_side(&tri, &mut out, |p| p.y - 1.0, Keep::Positive);
        // The tip above y = 1: a triangle of half the base and half the height.
        assert_eq!(out.len(), 3);
        assert!(out.iter().all(|p| p.y >= 1.0 - 1e-15));
        let snapped = |a: DVec3, b: DVec3| {
            let mut q = a + (b - a) * ((a.y - 1.0) / (a.y - b.y));
            q.y = 1.0;
            q
        };
        clip_polygon(&tri, &mut out, |p| p.y >= 1.0, snapped);
        assert_eq!(out.iter().filter(|p| p.y == 1.0).count(), 2);
    }
}
