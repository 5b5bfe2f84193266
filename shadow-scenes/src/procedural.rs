//! Procedural meshes for built-in scenes and tests: quads, boxes, spheres and grass blades.
//! All are returned as `(positions, triangles)` with counter-clockwise outward faces.

use std::f32::consts::{PI, TAU};

use glam::Vec3;

use shadow_core::sampling::{hash_words, unit_float};

/// A mesh as positions and triangles.
pub type Mesh = (Vec<Vec3>, Vec<[u32; 3]>);

/// A parallelogram `center ± u ± v` facing `u x v` (two triangles).
pub fn quad(center: Vec3, half_u: Vec3, half_v: Vec3) -> Mesh {
    (
        vec![
            center - half_u - half_v,
            center + half_u - half_v,
            center + half_u + half_v,
            center - half_u + half_v,
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    )
}

/// A horizontal square of side `size` at height `y`, facing +Y.
pub fn floor(size: f32, y: f32) -> Mesh {
    quad(
        Vec3::new(0.0, y, 0.0),
        Vec3::new(0.0, 0.0, 0.5 * size),
        Vec3::new(0.5 * size, 0.0, 0.0),
    )
}

/// A closed axis-aligned box with outward faces (or inward faces for a room).
pub fn cuboid(min: Vec3, max: Vec3, inward: bool) -> Mesh {
    let p: Vec<Vec3> = (0..8)
        .map(|i| {
            Vec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            )
        })
        .collect();
    let quads = [
        [0, 2, 3, 1], // -z
        [4, 5, 7, 6], // +z
        [0, 1, 5, 4], // -y
        [2, 6, 7, 3], // +y
        [0, 4, 6, 2], // -x
        [1, 3, 7, 5], // +x
    ];
    let mut t = Vec::new();
    for q in quads {
        let (a, b) = ([q[0], q[1], q[2]], [q[0], q[2], q[3]]);
        if inward {
            t.push([a[0], a[2], a[1]]);
            t.push([b[0], b[2], b[1]]);
        } else {
            t.push(a);
            t.push(b);
        }
    }
    (p, t)
}

/// A closed UV sphere with `rings` latitude bands and `segments` longitude segments, welded at
/// the poles and the seam.
pub fn uv_sphere(center: Vec3, radius: f32, rings: u32, segments: u32) -> Mesh {
    let rings = rings.max(2);
    let segments = segments.max(3);
    let mut p = vec![center + Vec3::Y * radius];
    for r in 1..rings {
        let theta = PI * r as f32 / rings as f32;
        for s in 0..segments {
            let phi = TAU * s as f32 / segments as f32;
            p.push(
                center
                    + radius
                        * Vec3::new(
                            theta.sin() * phi.cos(),
                            theta.cos(),
                            -theta.sin() * phi.sin(),
                        ),
            );
        }
    }
    p.push(center - Vec3::Y * radius);
    let bottom = p.len() as u32 - 1;
    let idx = |r: u32, s: u32| 1 + (r - 1) * segments + s % segments;
    let mut t = Vec::new();
    for s in 0..segments {
        t.push([0, idx(1, s), idx(1, s + 1)]);
    }
    for r in 1..rings - 1 {
        for s in 0..segments {
            let (a, b, c, d) = (idx(r, s), idx(r, s + 1), idx(r + 1, s), idx(r + 1, s + 1));
            t.push([a, c, d]);
            t.push([a, d, b]);
        }
    }
    for s in 0..segments {
        t.push([idx(rings - 1, s), bottom, idx(rings - 1, s + 1)]);
    }
    (p, t)
}

/// `count` thin open grass blades over the square `[-half, half]^2` (y = 0 up to `height`),
/// placed by a seeded hash: each blade is a tapered quad of two triangles, tilted at random.
pub fn grass(count: u32, half: f32, height: f32, width: f32, seed: u64) -> Mesh {
    let mut p = Vec::with_capacity(count as usize * 4);
    let mut t = Vec::with_capacity(count as usize * 2);
    for i in 0..count {
        let r = |k: u64| unit_float(hash_words(&[seed, i as u64, k]));
        let base = Vec3::new((2.0 * r(0) - 1.0) * half, 0.0, (2.0 * r(1) - 1.0) * half);
        let yaw = TAU * r(2);
        let across = Vec3::new(yaw.cos(), 0.0, yaw.sin());
        let lean = Vec3::new(-yaw.sin(), 0.0, yaw.cos()) * (0.35 * (2.0 * r(3) - 1.0));
        let h = height * (0.6 + 0.4 * r(4));
        let w = width * (0.7 + 0.6 * r(5));
        let tip = base + (Vec3::Y + lean).normalize() * h;
        let b = p.len() as u32;
        p.push(base - 0.5 * w * across);
        p.push(base + 0.5 * w * across);
        p.push(tip + 0.1 * w * across);
        p.push(tip - 0.1 * w * across);
        t.push([b, b + 1, b + 2]);
        t.push([b, b + 2, b + 3]);
    }
    (p, t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use shadow_core::topology::Topology;

    #[test]
    fn closed_meshes_are_closed() {
        for (name, (_, t)) in [
            ("box", cuboid(Vec3::ZERO, Vec3::ONE, false)),
            ("room", cuboid(Vec3::ZERO, Vec3::ONE, true)),
            ("sphere", uv_sphere(Vec3::ZERO, 1.0, 8, 12)),
        ] {
            let topo = Topology::build(&t);
            assert_eq!(topo.components().len(), 1, "{name}");
            assert!(topo.components()[0].closed, "{name}");
            assert!(topo.components()[0].consistently_oriented, "{name}");
        }
    }

    #[test]
    fn outward_faces_point_out() {
        let (p, t) = uv_sphere(Vec3::ZERO, 1.0, 8, 12);
        for tri in &t {
            let [a, b, c] = tri.map(|i| p[i as usize]);
            let n = (b - a).cross(c - a);
            assert!(n.dot(a + b + c) > 0.0);
        }
        let (p, t) = cuboid(Vec3::splat(-1.0), Vec3::ONE, false);
        for tri in &t {
            let [a, b, c] = tri.map(|i| p[i as usize]);
            assert!((b - a).cross(c - a).dot(a + b + c) > 0.0);
        }
    }
}
