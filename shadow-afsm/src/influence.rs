//! The influence region of a caster triangle (section 4.1) computed on the CPU exactly as
//! `influence.wgsl` does on the GPU, so tests compare the GPU stage against it, and so the
//! construction is documented in one readable place:
//!
//! for every vertex `v` and every point `y` bounding the light (corners, outline, the octagon
//! around a disk, or for spheres the regular hexagon around the silhouette circle of the
//! sphere seen from `v`), the line from `y` through `v` meets the far plane at
//! `f = v + s (v - y)`, `s = (z_far - z_v) / (z_v - z_y)`; the convex hull of the vertices'
//! projections and of every `f`, in texel coordinates, bounds the texels whose view samples the
//! triangle can shadow.

use glam::{Vec2, Vec3};

use crate::frame::MapFrame;
use crate::params::{Caster, KIND_DISK, KIND_POINT, KIND_SPHERE, LightBounds, Region};

/// The influence region of one caster.
#[derive(Debug, Clone, PartialEq)]
pub enum Influence {
    /// The triangle shadows none of the listed view samples (or is a light front-facing
    /// triangle of a closed mesh).
    Culled,
    /// A vertex is not beyond the light along the frustum axis: the whole map.
    WholeMap,
    /// A convex hull in texel coordinates, counter-clockwise.
    Hull(Vec<Vec2>),
}

/// Convex hull (monotone chain, `shadow_core::geometry::convex_hull`), counter-clockwise,
/// collinear points dropped, in texel coordinates.
pub fn convex_hull(pts: Vec<Vec2>) -> Vec<Vec2> {
    shadow_core::geometry::convex_hull(pts.into_iter().map(|p| p.as_dvec2()).collect())
        .into_iter()
        .map(|p| p.as_vec2())
        .collect()
}

/// The points bounding the light as seen through vertex `v`, or `None` when `v` is inside a
/// sphere light.
fn light_points(b: &LightBounds, v: Vec3) -> Option<Vec<Vec3>> {
    Some(match b.kind {
        KIND_DISK => {
            let rad = b.radius / (std::f32::consts::PI / 8.0).cos();
            (0..8)
                .map(|j| {
                    let a = j as f32 * std::f32::consts::PI / 4.0;
                    b.center + rad * (a.cos() * b.axes[0] + a.sin() * b.axes[1])
                })
                .collect()
        }
        KIND_SPHERE => {
            let w = v - b.center;
            let l2 = w.dot(w);
            let rs = b.radius;
            if l2 <= rs * rs * 1.0001 {
                return None;
            }
            let axis = w / l2.sqrt();
            let mid = b.center + (rs * rs / l2) * w;
            let rho = rs * (1.0 - rs * rs / l2).max(0.0).sqrt();
            let mut e1 = axis.cross(Vec3::Y);
            if e1.dot(e1) < 1e-6 {
                e1 = axis.cross(Vec3::X);
            }
            let e1 = e1.normalize();
            let e2 = axis.cross(e1);
            let rad = rho / (std::f32::consts::PI / 6.0).cos();
            (0..6)
                .map(|j| {
                    let a = j as f32 * std::f32::consts::PI / 3.0;
                    mid + rad * (a.cos() * e1 + a.sin() * e2)
                })
                .collect()
        }
        KIND_POINT => Vec::new(),
        _ => b.outline.clone(),
    })
}

/// The influence region of `caster` in `frame`.
pub fn influence(caster: &Caster, b: &LightBounds, frame: &MapFrame) -> Influence {
    let v = caster.vertices();
    let nt = (v[1] - v[0]).cross(v[2] - v[0]);
    let (lo, _) = b.range(nt);
    if caster.closed() && lo - nt.dot(v[0]) > 0.0 {
        return Influence::Culled;
    }
    let (c, d, far) = (frame.center, frame.d, frame.far);
    if v.iter().map(|p| (*p - c).dot(d)).fold(f32::MAX, f32::min) > far {
        return Influence::Culled;
    }
    // Wholly before the light's nearest point along the axis (`influence.wgsl`).
    let light_near = b.range(d).0 - d.dot(c);
    if v.iter().map(|p| (*p - c).dot(d)).fold(f32::MIN, f32::max) < light_near - 1e-5 * far {
        return Influence::Culled;
    }
    let mut pts = Vec::new();
    for vk in v {
        let zv = (vk - c).dot(d);
        if zv <= 1e-6 * far {
            return Influence::WholeMap;
        }
        pts.push(frame.to_texel(frame.project(vk).truncate()));
        let Some(ys) = light_points(b, vk) else {
            return Influence::WholeMap;
        };
        for y in ys {
            let zy = (y - c).dot(d);
            if zv - zy <= 1e-6 * far {
                return Influence::WholeMap;
            }
            let s = (far - zv) / (zv - zy);
            let q = vk + s * (vk - y) - c;
            pts.push(frame.to_texel(Vec2::new(q.dot(frame.u), q.dot(frame.v)) / far));
        }
    }
    let side = frame.side as f32;
    let (lo, hi) = pts.iter().fold(
        (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN)),
        |(l, h), p| (l.min(*p), h.max(*p)),
    );
    if hi.x < -1e-3 || hi.y < -1e-3 || lo.x > side + 1e-3 || lo.y > side + 1e-3 {
        return Influence::Culled;
    }
    Influence::Hull(convex_hull(pts))
}

/// Conservative rasterisation (section 3.2) as `tiling.wgsl` does it: texel `(tx, ty)` of the
/// region's box overlaps a read-back region's hull (separating axes of the hull's edges, with
/// the shader's 1e-3 texel margin). Regions flagged whole-map or degenerate overlap every
/// texel of their box.
pub fn texel_overlaps(region: &Region, tx: i32, ty: i32) -> bool {
    let [h, flag, _, _] = region.info;
    if flag != 0 || h < 3 {
        return true;
    }
    let h = h as usize;
    let lo = Vec2::new(tx as f32, ty as f32) - Vec2::splat(1e-3);
    let hi = lo + Vec2::splat(1.0 + 2e-3);
    (0..h).all(|k| {
        let a = Vec2::from(region.pts[k]);
        let e = Vec2::from(region.pts[(k + 1) % h]) - a;
        let n = Vec2::new(-e.y, e.x);
        let corner = Vec2::new(
            if n.x > 0.0 { hi.x } else { lo.x },
            if n.y > 0.0 { hi.y } else { lo.y },
        );
        n.dot(corner - a) >= 0.0
    })
}

/// The occlusion work of read-back regions over read-back list offsets (`side^2 + 1`): the
/// texels with a list that overlap a region, and the (caster, view sample) pairs they hold,
/// as the `tile_pairs` pass tallies them.
pub fn occlusion_work(regions: &[Region], offsets: &[u32], side: u32) -> (u64, u64) {
    let (mut texels, mut pairs) = (0u64, 0u64);
    for r in regions {
        for ty in r.bbox[1]..=r.bbox[3] {
            for tx in r.bbox[0]..=r.bbox[2] {
                let t = (ty as u32 * side + tx as u32) as usize;
                let len = (offsets[t + 1] - offsets[t]) as u64;
                if len > 0 && texel_overlaps(r, tx, ty) {
                    texels += 1;
                    pairs += len;
                }
            }
        }
    }
    (texels, pairs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_of_a_square_with_inner_points_is_the_square() {
        let pts = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.5, 0.5),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
            Vec2::new(0.5, 0.0),
        ];
        let h = convex_hull(pts);
        assert_eq!(h.len(), 4);
        // Counter-clockwise: positive signed area.
        let area: f32 = (0..4).map(|i| h[i].perp_dot(h[(i + 1) % 4])).sum::<f32>() / 2.0;
        assert!((area - 1.0).abs() < 1e-6);
    }
}
