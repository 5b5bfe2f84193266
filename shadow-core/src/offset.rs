//! Robust ray origins after Wachter and Binder, "A Fast and Robust Method for Avoiding
//! Self-Intersection", Ray Tracing Gems ch. 6: the origin is moved along the normal by a fixed
//! number of float ULPs (integer arithmetic on the bit pattern), and near the origin, where ULPs
//! vanish, by a small absolute step.
//!
//! The ULP step is 32 rather than the chapter's 256: view-sample positions here are exact ray-plane
//! hits rounded once (computed in f64), and the receiver's own triangle is excluded from its
//! occlusion queries, so a small step suffices and contact shadows stay tight.
//!
//! The chapter's absolute constants (1/32 and 1/65536) assume scenes of unit size; here they are
//! scaled by the scene's extent, so a scene scaled by 1e-4 or 1e5 gets the same relative offset
//! (the stress suite checks this invariance).

use glam::Vec3;

/// ULP offset scale (the chapter's `int_scale`).
const INT_SCALE: f32 = 32.0;

/// Offsets positions off their surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayOffset {
    origin: f32,
    float_scale: f32,
}

impl RayOffset {
    /// Offsets for a scene whose bounding-box diagonal is `extent`.
    pub fn for_extent(extent: f32) -> Self {
        let e = if extent.is_finite() && extent > 0.0 {
            extent
        } else {
            1.0
        };
        Self {
            origin: e / 32.0,
            float_scale: e / 65536.0,
        }
    }

    /// `p` moved off its surface toward the side `n` (unit) points to.
    pub fn offset(&self, p: Vec3, n: Vec3) -> Vec3 {
        let of_i = (INT_SCALE * n).as_ivec3();
        let bump = |p: f32, o: i32| -> f32 {
            let bits = p.to_bits() as i32;
            let moved = if p < 0.0 {
                bits.wrapping_sub(o)
            } else {
                bits.wrapping_add(o)
            };
            f32::from_bits(moved as u32)
        };
        let pi = Vec3::new(bump(p.x, of_i.x), bump(p.y, of_i.y), bump(p.z, of_i.z));
        let pick = |p: f32, pi: f32, n: f32| {
            if p.abs() < self.origin {
                p + self.float_scale * n
            } else {
                pi
            }
        };
        Vec3::new(
            pick(p.x, pi.x, n.x),
            pick(p.y, pi.y, n.y),
            pick(p.z, pi.z, n.z),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_moves_to_the_normal_side() {
        let o = RayOffset::for_extent(10.0);
        for p in [
            Vec3::new(3.0, 0.0, -2.0),
            Vec3::new(1e4, 1e4, 1e4),
            Vec3::new(-5.0, 1e-3, 7.0),
        ] {
            let n = Vec3::new(0.3, 0.9, -0.2).normalize();
            let q = o.offset(p, n);
            assert!((q - p).dot(n) > 0.0, "{p:?}");
            assert!((q - p).length() < 1e-2 * (1.0 + p.length()));
        }
    }
}
