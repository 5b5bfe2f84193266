//! Unshadowed diffuse irradiance from planar lights in closed form, and the ratio estimator of
//! shadowed direct light (Heitz, Hill and McGuire, "Combining Analytic Direct Illumination and
//! Stochastic Shadows", I3D 2018).
//!
//! The unshadowed irradiance is the same integral that DCS eq. 6 estimates with every sample
//! visible: `E(p) = L * integral over the light of max(0, n_s . w) [n_g . w > 0] dw`, where `w`
//! runs over the directions from `p` to the light's front side, `n_s` is the shading normal
//! (the cosine) and `n_g` the geometric normal (a receiver takes no light from behind its
//! surface, DESIGN section 3). Both conditions are half-spaces through `p`, so the integral
//! is `L n_s . Phi` with `Phi` the vector irradiance (Arvo 1994) of the part of the light above
//! both planes. `Phi` is a boundary integral, `(1/2) closed integral of x cross dx / |x|^2`
//! with `x` relative to `p` (Lambert's formula for polygons):
//! * rectangles and polygons are clipped by the two planes (Sutherland-Hodgman; degenerate
//!   edges of a concave polygon's clip cancel in the boundary integral) and summed edge by edge,
//!   `theta_i * normalize(x_i cross x_i+1) / 2`;
//! * a disk's region is the disk cut by up to two lines in its plane; its boundary is arcs of the
//!   circle and chords of the lines, and along an arc the integral has the elementary
//!   antiderivatives of `1, cos, sin` over `A + B cos + C sin` (the exact form factor of a disk
//!   of any orientation, horizon included).
//!
//! The ratio estimator multiplies this exact unshadowed term by the share of it that the
//! samples see: `E_ratio = E_closed * sum f_k v_k / sum f_k`, with `f_k` the eq. 6 term of
//! sample `k` (cosines, inverse squared distance, the horizon) and `v_k` its visibility from a
//! sample-based technique. Where nothing occludes, it returns the closed form exactly; in
//! penumbrae it keeps only the noise of the visible fraction, not that of the cosines and
//! distances.

use glam::{DVec2, DVec3, Vec3};

use crate::clip::{Keep, clip_by_side};
use crate::light::{AreaLight, LightGeometry, LightSample, Radiance};
use crate::view_samples::ViewSample;

/// The vector irradiance `Phi` (unit radiance) of the part of a planar light that lies above
/// the planes through `p` with normals `n_g` and `n_s`, its front side facing `p`; `None` for
/// lights that are not planar (spheres, points).
pub fn vector_irradiance(
    geometry: &LightGeometry<'_>,
    p: Vec3,
    n_g: Vec3,
    n_s: Vec3,
) -> Option<DVec3> {
    let p = p.as_dvec3();
    // Flat shading gives one plane twice: a disk's chord along it must be counted once.
    let planes: &[DVec3] = if n_g == n_s {
        &[n_g.as_dvec3()]
    } else {
        &[n_g.as_dvec3(), n_s.as_dvec3()]
    };
    let (phi, normal) = match *geometry {
        LightGeometry::Rectangle {
            center,
            half_u,
            half_v,
            normal,
        } => {
            let (c, u, v) = (center.as_dvec3(), half_u.as_dvec3(), half_v.as_dvec3());
            let corners = [c - u - v, c + u - v, c + u + v, c - u + v];
            (polygon_phi(&corners, p, planes), normal.as_dvec3())
        }
        LightGeometry::Polygon { outline, normal } => {
            let pts: Vec<DVec3> = outline.iter().map(|v| v.as_dvec3()).collect();
            (polygon_phi(&pts, p, planes), normal.as_dvec3())
        }
        LightGeometry::Disk {
            center,
            normal,
            radius,
        } => (
            disk_phi(
                center.as_dvec3(),
                normal.as_dvec3(),
                f64::from(radius),
                p,
                planes,
            ),
            normal.as_dvec3(),
        ),
        LightGeometry::Sphere { .. } | LightGeometry::Point { .. } | LightGeometry::Mesh { .. } => {
            return None;
        }
    };
    // Only the light's front side emits: nothing when `p` is behind or in its plane.
    let centre = geometry_centre(geometry)?;
    if (p - centre).dot(normal) <= 0.0 {
        return Some(DVec3::ZERO);
    }
    // Every direction to the front side has a negative component along the light's normal, so
    // `Phi` does: that fixes the orientation of the boundary integral.
    Some(if phi.dot(normal) > 0.0 { -phi } else { phi })
}

fn geometry_centre(g: &LightGeometry<'_>) -> Option<DVec3> {
    match *g {
        LightGeometry::Rectangle { center, .. } | LightGeometry::Disk { center, .. } => {
            Some(center.as_dvec3())
        }
        LightGeometry::Polygon { outline, .. } => outline.first().map(|v| v.as_dvec3()),
        LightGeometry::Sphere { .. } | LightGeometry::Point { .. } | LightGeometry::Mesh { .. } => {
            None
        }
    }
}

/// Outgoing radiance at view sample `s` of albedo `albedo` under diffuse shading with every
/// light sample visible: `albedo / pi * E(p)`, in closed form. `None` where there is no closed
/// form here: a textured light, a sphere or a point light.
pub fn unshadowed_direct(s: &ViewSample, albedo: Vec3, light: &dyn AreaLight) -> Option<Vec3> {
    let Radiance::Constant(l) = light.radiance() else {
        return None;
    };
    let phi = vector_irradiance(
        &light.geometry(),
        s.position,
        s.geometric_normal,
        s.shading_normal,
    )?;
    let e = s.shading_normal.as_dvec3().dot(phi).max(0.0);
    Some(albedo * *l * (e * std::f64::consts::FRAC_1_PI) as f32)
}

/// The ratio estimator of one pixel: the closed-form unshadowed radiance times the share of the
/// eq. 6 terms of `samples` that `visibility(k)` lets through. `None` where
/// [`unshadowed_direct`] has no closed form (the caller keeps eq. 6 there).
pub fn pixel_ratio_direct(
    s: &ViewSample,
    albedo: Vec3,
    light: &dyn AreaLight,
    samples: &[LightSample],
    visibility: impl Fn(usize) -> f32,
) -> Option<Vec3> {
    let closed = unshadowed_direct(s, albedo, light)?;
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for (k, y) in samples.iter().enumerate() {
        if (y.position - s.position).dot(s.geometric_normal) <= 0.0 {
            continue;
        }
        // The scalar part of the eq. 6 term (albedo and radiance are common factors).
        let f =
            f64::from(crate::direct::sample_term(s, Vec3::ONE, y, false).x * std::f32::consts::PI);
        den += f;
        num += f * f64::from(visibility(k));
    }
    Some(if den > 0.0 {
        closed * (num / den) as f32
    } else {
        Vec3::ZERO
    })
}

/// Keeps the part of the polygon `pts` (relative to the origin) with `x . n > 0`.
fn clip(pts: &[DVec3], n: DVec3) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(pts.len() + 2);
    clip_by_side(pts, &mut out, |x| x.dot(n), Keep::Positive);
    out
}

/// Lambert's formula over the polygon `corners` clipped by the planes through `p`.
fn polygon_phi(corners: &[DVec3], p: DVec3, planes: &[DVec3]) -> DVec3 {
    let mut pts: Vec<DVec3> = corners.iter().map(|c| *c - p).collect();
    for n in planes {
        if n.length_squared() > 0.0 {
            pts = clip(&pts, *n);
        }
    }
    let mut phi = DVec3::ZERO;
    for (i, &a) in pts.iter().enumerate() {
        phi += edge_phi(a, pts[(i + 1) % pts.len()]);
    }
    phi
}

/// One straight edge's term, `theta * normalize(a cross b) / 2`.
fn edge_phi(a: DVec3, b: DVec3) -> DVec3 {
    let c = a.cross(b);
    let len = c.length();
    if !(len > 0.0) {
        return DVec3::ZERO;
    }
    let theta = len.atan2(a.dot(b));
    c * (0.5 * theta / len)
}

/// A half-plane `alpha X + beta Y + gamma > 0` in the disk's plane coordinates.
#[derive(Clone, Copy)]
struct HalfPlane {
    n: DVec2,
    gamma: f64,
}

/// The disk `(center, normal, radius)` cut by the planes through `p`, integrated along its
/// boundary: the arcs of the circle inside both half-planes and the chords of the lines inside
/// the disk and the other half-plane, oriented counter-clockwise in the disk's `(t, b)` frame.
fn disk_phi(center: DVec3, normal: DVec3, radius: f64, p: DVec3, planes: &[DVec3]) -> DVec3 {
    let (t, b) = basis(normal);
    let d = center - p;
    let halves: Vec<HalfPlane> = planes
        .iter()
        .filter(|n| n.length_squared() > 0.0)
        .map(|n| HalfPlane {
            n: DVec2::new(n.dot(t), n.dot(b)),
            gamma: n.dot(d),
        })
        .collect();
    // The arcs: intervals of the circle's angle inside every half-plane.
    let mut arcs = vec![(0.0, std::f64::consts::TAU)];
    for h in &halves {
        let rho = h.n.length();
        if rho * radius <= h.gamma.abs() {
            if h.gamma <= 0.0 {
                return DVec3::ZERO; // the whole disk is behind this plane
            }
            continue;
        }
        let delta = (-h.gamma / (rho * radius)).acos();
        let phi = h.n.y.atan2(h.n.x);
        arcs = intersect(&arcs, (phi - delta, 2.0 * delta));
    }
    let mut total = DVec3::ZERO;
    for (start, len) in arcs {
        total += arc_phi(d, t, b, radius, start, len);
    }
    // The chords.
    for (i, h) in halves.iter().enumerate() {
        let rho2 = h.n.length_squared();
        let rho = rho2.sqrt();
        if rho * radius <= h.gamma.abs() {
            continue;
        }
        let dir = DVec2::new(h.n.y, -h.n.x) / rho; // the half-plane on its left
        let foot = -h.gamma * h.n / rho2;
        let half = (radius * radius - h.gamma * h.gamma / rho2).max(0.0).sqrt();
        let (mut lo, mut hi) = (-half, half);
        for (j, o) in halves.iter().enumerate() {
            if i == j {
                continue;
            }
            // o.n . (foot + s dir) + o.gamma > 0
            let (a, k) = (o.n.dot(foot) + o.gamma, o.n.dot(dir));
            if k.abs() < 1e-300 {
                if a <= 0.0 {
                    hi = lo;
                }
            } else if k > 0.0 {
                lo = lo.max(-a / k);
            } else {
                hi = hi.min(-a / k);
            }
        }
        if hi > lo {
            let at = |s: f64| {
                let q = foot + s * dir;
                d + q.x * t + q.y * b
            };
            total += edge_phi(at(lo), at(hi));
        }
    }
    total
}

/// Unit vectors spanning the plane of `n`.
fn basis(n: DVec3) -> (DVec3, DVec3) {
    let t = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let t = (t - n * n.dot(t)).normalize();
    (t, n.cross(t))
}

/// Intersects circular intervals `(start, length)` with one more.
fn intersect(arcs: &[(f64, f64)], (s2, l2): (f64, f64)) -> Vec<(f64, f64)> {
    use std::f64::consts::TAU;
    let mut out = Vec::new();
    for &(s1, l1) in arcs {
        let off = (s2 - s1).rem_euclid(TAU);
        for o in [off, off - TAU] {
            let (a, b) = (o.max(0.0), (o + l2).min(l1));
            if b > a {
                out.push((s1 + a, b - a));
            }
        }
    }
    out
}

/// `(1/2) integral of x cross dx / |x|^2` along the circle `d + r (cos th t + sin th b)` for `th`
/// from `start` over `len`, in pieces of at most a quarter turn so the antiderivatives stay on
/// one branch.
fn arc_phi(d: DVec3, t: DVec3, b: DVec3, r: f64, start: f64, len: f64) -> DVec3 {
    let pieces = (len / std::f64::consts::FRAC_PI_2).ceil().max(1.0) as usize;
    let step = len / pieces as f64;
    // |x|^2 = A + B cos th + C sin th.
    let a = d.length_squared() + r * r;
    let (bb, cc) = (2.0 * r * d.dot(t), 2.0 * r * d.dot(b));
    let k = bb.hypot(cc);
    let psi = cc.atan2(bb);
    let s = ((a - k) * (a + k)).max(0.0).sqrt();
    let (mut i0, mut ic, mut is) = (0.0, 0.0, 0.0);
    for j in 0..pieces {
        let th0 = start + step * j as f64;
        let (u0, u1) = {
            let u0 = (th0 - psi + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            (u0, u0 + step)
        };
        // Integrals over u of 1, cos u, sin u divided by A + K cos u.
        let f0 = |u: f64| 2.0 / s * ((a - k) * (0.5 * u).sin()).atan2(s * (0.5 * u).cos());
        let p0 = f0(u1) - f0(u0);
        let (pc, ps) = if k > 1e-9 * a {
            (
                ((u1 - u0) - a * p0) / k,
                -((a + k * u1.cos()).ln() - (a + k * u0.cos()).ln()) / k,
            )
        } else {
            ((u1.sin() - u0.sin()) / a, -(u1.cos() - u0.cos()) / a)
        };
        // Back to th = u + psi.
        let (sp, cp) = psi.sin_cos();
        i0 += p0;
        ic += cp * pc - sp * ps;
        is += sp * pc + cp * ps;
    }
    // x cross dx = r d cross (-sin th t + cos th b) dth + r^2 (t cross b) dth.
    let v = r * (d.cross(b) * ic - d.cross(t) * is) + r * r * t.cross(b) * i0;
    0.5 * v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{DiskLight, PolygonLight, RectLight};
    use crate::sampling::{LightSampler, SamplingStrategy};
    use glam::UVec2;

    fn receiver(p: Vec3, n_g: Vec3, n_s: Vec3) -> ViewSample {
        ViewSample {
            pixel: UVec2::ZERO,
            position: p,
            geometric_normal: n_g,
            shading_normal: n_s,
            triangle: 0,
            depth: 1.0,
            albedo: None,
        }
    }

    /// Eq. 6 with every sample visible, from many stratified samples.
    fn monte_carlo(s: &ViewSample, light: &dyn AreaLight, n: u32) -> f64 {
        let sampler = LightSampler::new(SamplingStrategy::Stratified, n, 7).unwrap();
        let mut samples = Vec::new();
        sampler.light_samples(light, UVec2::new(3, 5), &mut samples);
        let visible = |k: usize| {
            if (samples[k].position - s.position).dot(s.geometric_normal) > 0.0 {
                1.0
            } else {
                0.0
            }
        };
        f64::from(crate::direct::pixel_direct(s, Vec3::ONE, light, &samples, visible).x)
    }

    fn receivers() -> Vec<ViewSample> {
        let up = Vec3::Y;
        let tilted = Vec3::new(0.6, 0.8, 0.0);
        let shaded = Vec3::new(-0.3, 0.9, 0.3).normalize();
        vec![
            receiver(Vec3::ZERO, up, up),
            receiver(Vec3::new(0.7, 0.2, -0.4), up, up),
            receiver(Vec3::new(0.2, 0.1, 0.3), tilted, tilted),
            receiver(Vec3::new(-0.5, 0.0, 0.1), up, shaded),
            // The light's plane cuts the receiver's horizon.
            receiver(Vec3::new(0.1, 0.9, 0.0), Vec3::X, Vec3::X),
            receiver(
                Vec3::new(0.0, 0.95, 0.2),
                Vec3::new(0.0, 0.2, 1.0).normalize(),
                Vec3::Z,
            ),
        ]
    }

    fn agree(light: &dyn AreaLight) {
        for s in receivers() {
            let exact = f64::from(unshadowed_direct(&s, Vec3::ONE, light).unwrap().x);
            let mc = monte_carlo(&s, light, 65536);
            let tol = 2e-3 * exact.abs().max(0.02);
            assert!(
                (exact - mc).abs() < tol,
                "{light:?} at {:?}: closed form {exact}, Monte Carlo {mc}",
                s.position
            );
        }
    }

    #[test]
    fn rectangle_matches_monte_carlo_horizon_included() {
        let l = RectLight::facing(
            Vec3::new(0.2, 1.0, 0.1),
            Vec3::NEG_Y,
            0.8,
            0.5,
            Radiance::Constant(Vec3::ONE),
        )
        .unwrap();
        agree(&l);
    }

    #[test]
    fn disk_matches_monte_carlo_horizon_included() {
        let tilted = Vec3::new(0.3, -1.0, 0.2).normalize();
        for n in [Vec3::NEG_Y, tilted] {
            let l = DiskLight::new(
                Vec3::new(0.1, 1.0, -0.1),
                n,
                0.45,
                Radiance::Constant(Vec3::ONE),
            )
            .unwrap();
            agree(&l);
        }
    }

    #[test]
    fn concave_polygon_matches_monte_carlo() {
        // Wound so that the right-hand normal faces down, toward the receivers.
        let outline = vec![
            Vec3::new(0.5, 1.0, -0.5),
            Vec3::new(0.5, 1.0, 0.5),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(-0.5, 1.0, 0.5),
            Vec3::new(-0.5, 1.0, -0.5),
        ];
        let l = PolygonLight::new(outline, Radiance::Constant(Vec3::ONE)).unwrap();
        agree(&l);
    }

    /// The disk of radius `r` straight above at height `h` on a parallel receiver: the
    /// textbook form factor `r^2 / (r^2 + h^2)`.
    #[test]
    fn parallel_disk_gives_the_textbook_form_factor() {
        let (r, h) = (0.4f32, 1.3f32);
        let l = DiskLight::new(
            Vec3::new(0.0, h, 0.0),
            Vec3::NEG_Y,
            r,
            Radiance::Constant(Vec3::ONE),
        )
        .unwrap();
        let s = receiver(Vec3::ZERO, Vec3::Y, Vec3::Y);
        let e = f64::from(unshadowed_direct(&s, Vec3::ONE, &l).unwrap().x);
        let f = f64::from(r * r / (r * r + h * h));
        assert!((e - f).abs() < 1e-6, "{e} against {f}");
    }

    #[test]
    fn behind_the_light_there_is_nothing() {
        let l = RectLight::facing(
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::NEG_Y,
            1.0,
            1.0,
            Radiance::Constant(Vec3::ONE),
        )
        .unwrap();
        let s = receiver(Vec3::new(0.0, 2.0, 0.0), Vec3::NEG_Y, Vec3::NEG_Y);
        assert_eq!(unshadowed_direct(&s, Vec3::ONE, &l), Some(Vec3::ZERO));
    }

    #[test]
    fn the_ratio_estimator_is_exact_without_occluders() {
        let l = DiskLight::new(
            Vec3::new(0.1, 1.0, -0.1),
            Vec3::NEG_Y,
            0.45,
            Radiance::Constant(Vec3::ONE),
        )
        .unwrap();
        let sampler = LightSampler::new(SamplingStrategy::Stratified, 16, 3).unwrap();
        let mut samples = Vec::new();
        for s in receivers() {
            sampler.light_samples(&l, UVec2::new(1, 2), &mut samples);
            let closed = unshadowed_direct(&s, Vec3::ONE, &l).unwrap();
            let ratio = pixel_ratio_direct(&s, Vec3::ONE, &l, &samples, |_| 1.0).unwrap();
            if samples
                .iter()
                .any(|y| (y.position - s.position).dot(s.geometric_normal) > 0.0)
            {
                assert!((ratio - closed).abs().max_element() <= 1e-6 * closed.x.max(1e-3));
            }
        }
    }
}
