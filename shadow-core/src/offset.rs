//! Robust ray origins after Wachter and Binder, "A Fast and Robust Method for Avoiding
//! Self-Intersection", Ray Tracing Gems ch. 6, adapted to how view samples are made here.
//!
//! The chapter moves a hit point along its normal by a fixed number of float ULPs of each
//! coordinate, and near the origin, where ULPs vanish, by an absolute step sized for a scene of
//! unit extent. Both terms here follow the point, never the scene's extent (a 200 km floor or
//! one far vertex must not push a receiver past a 1 m occluder, issue 51 item 5):
//!
//! * **the point's own rounding.** View-sample positions are exact ray-plane hits rounded once
//!   (computed in f64), so each coordinate is off its triangle by at most half a ULP of itself;
//!   moving `ULPS` ULPs of the largest coordinate along the normal clears it with margin. This
//!   term scales with the point's magnitude (translation), as in the chapter.
//! * **the shadow ray's length.** Where coordinates are small (near the origin), the step is a
//!   fixed fraction (`2^-18`) of the distance from the point to the light (at least the light's
//!   radius): the error of intersecting the rays of length `d` with geometry near the point is
//!   relative to `d`, and a receiver moved by `d 2^-18` toward the light sees the light's
//!   penumbra change by that relative amount, far below any technique's budget.
//!
//! Scaling the scene scales both terms (the stress suite checks scale invariance); the
//! receiver's own triangle is excluded from its occlusion queries, so contact shadows stay
//! tight. Moving along the normal with one float addition per coordinate never moves a
//! coordinate against the normal, and the largest coordinate of the normal moves by at least
//! `ULPS / sqrt(3)` of its ULPs.

use glam::Vec3;

/// ULPs of the point's largest coordinate that the origin moves along the normal.
const ULPS: f32 = 4.0;
/// Fraction of the distance to the light that the origin moves along the normal.
const RAY_FRACTION: f32 = 1.0 / 262_144.0;

/// Offsets view-sample positions off their surface, for shadow rays toward one light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayOffset {
    light_centre: Vec3,
    light_radius: f32,
}

impl RayOffset {
    /// Offsets for shadow rays toward a light centred at `centre` with bounding radius `radius`.
    /// Non-finite inputs fall back to the origin and zero (the point's own rounding still holds).
    pub fn toward(centre: Vec3, radius: f32) -> Self {
        Self {
            light_centre: if centre.is_finite() {
                centre
            } else {
                Vec3::ZERO
            },
            light_radius: if radius.is_finite() {
                radius.max(0.0)
            } else {
                0.0
            },
        }
    }

    /// Offsets for shadow rays toward `light` (its centre and half its bounds' diagonal).
    pub fn for_light(light: &dyn crate::light::AreaLight) -> Self {
        Self::toward(light.center(), 0.5 * light.bounds().diagonal())
    }

    /// How far [`RayOffset::offset`] moves `p` along its normal.
    pub fn step(&self, p: Vec3) -> f32 {
        let m = p.abs().max_element();
        let ulp = f32::from_bits(m.to_bits().saturating_add(1)) - m;
        let d = p.distance(self.light_centre).max(self.light_radius);
        let step = (ULPS * ulp).max(RAY_FRACTION * d);
        if step.is_finite() { step } else { ULPS * ulp }
    }

    /// `p` moved off its surface toward the side `n` (unit) points to.
    pub fn offset(&self, p: Vec3, n: Vec3) -> Vec3 {
        p + n * self.step(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_moves_to_the_normal_side() {
        let o = RayOffset::toward(Vec3::new(0.0, 3.0, 0.0), 0.5);
        for p in [
            Vec3::new(3.0, 0.0, -2.0),
            Vec3::new(1e4, 1e4, 1e4),
            Vec3::new(-5.0, 1e-3, 7.0),
            Vec3::new(1e6, 1e6, 1e6),
        ] {
            let n = Vec3::new(0.3, 0.9, -0.2).normalize();
            let q = o.offset(p, n);
            assert!((q - p).dot(n) > 0.0, "{p:?}");
            assert!((q - p).length() < 1e-2 * (1.0 + p.length()));
        }
    }

    /// Issue 51 item 5: a receiver under a light 3 m above it moves by micrometres whatever else
    /// the scene holds (a 200 km floor made the step 4 m).
    #[test]
    fn step_follows_the_point_and_the_light_not_the_scene() {
        let o = RayOffset::toward(Vec3::new(0.0, 3.0, 0.0), 0.5);
        let q = o.offset(Vec3::new(0.2, 0.0, -0.1), Vec3::Y);
        assert!(q.y > 0.0 && q.y < 2e-5, "{q:?}");
        // Far from the origin the point's own ULPs rule: 4 of them.
        let p = Vec3::new(1e5, 0.0, 0.0);
        let far = RayOffset::toward(p + Vec3::Y * 3.0, 0.5);
        let q = far.offset(p, Vec3::Y);
        assert!(q.y > 0.0 && q.y <= 4.0 * 0.0079, "{q:?}");
    }

    #[test]
    fn step_scales_with_the_scene() {
        for s in [1e-4f32, 1.0, 1e5] {
            let o = RayOffset::toward(Vec3::new(0.0, 2.0, 0.0) * s, 0.5 * s);
            let step = o.step(Vec3::new(0.1, 0.0, 0.1) * s);
            let rel = step / s;
            assert!((rel - 2.0 * RAY_FRACTION).abs() < 0.1 * rel, "{s}: {rel}");
        }
    }
}
