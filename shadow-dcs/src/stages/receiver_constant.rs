//! The integration constant `D(p, c)` of receivers without a camera (section 4.1): where no eye
//! point sees the receivers (a lightmap's texels, a path tracer's hit points, an orthographic
//! view), the shadow-volume step has nothing to count from, so each receiver's constant is
//! counted along its own segment from its ray origin to the light centre, with the rules of the
//! eye's constant ([`CrossingRule`]: one-sided closed meshes count the faces turned to the
//! light, semi-opaque faces their opacity in units).
//!
//! The segments are walked through a uniform grid over the triangles that count (3D DDA,
//! Amanatides and Woo 1987). A triangle is listed in every cell its padded box touches, and a
//! crossing is counted only in the cell whose stretch of the segment `[t_enter, t_exit)` holds
//! its hit parameter, so a triangle met in several cells counts once.

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use shadow_core::geometry::ray_triangle_t;
use shadow_core::scene::Scene;

use crate::stages::constant::CrossingRule;
use crate::stages::edges::Sides;

/// The most cells along one axis.
const MAX_CELLS_PER_AXIS: usize = 128;
/// Cells per counted triangle, about.
const CELLS_PER_TRIANGLE: f64 = 2.0;

/// The triangles that count toward the light centre, in a uniform grid.
pub(crate) struct CrossingGrid {
    lo: DVec3,
    hi: DVec3,
    cell: DVec3,
    dims: [usize; 3],
    /// Per cell, where its triangles start in `items` (one more entry than cells).
    starts: Vec<u32>,
    /// Indices into `triangles`.
    items: Vec<u32>,
    triangles: Vec<([DVec3; 3], i64)>,
}

impl CrossingGrid {
    /// The grid of `scene`'s triangles whose crossing toward the light centre `c` weighs
    /// anything.
    pub(crate) fn new(scene: &dyn Scene, units: u32, sides: &Sides, c: Vec3) -> Self {
        let rule = CrossingRule::new(scene, units, sides, c.as_dvec3());
        let triangles: Vec<([DVec3; 3], i64)> = (0..scene.triangle_count())
            .into_par_iter()
            .filter_map(|t| {
                let w = rule.weight(t);
                (w != 0).then(|| (scene.triangle(t).map(|v| v.as_dvec3()), w))
            })
            .collect();
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for (tri, _) in &triangles {
            for v in tri {
                lo = lo.min(*v);
                hi = hi.max(*v);
            }
        }
        if triangles.is_empty() {
            (lo, hi) = (DVec3::ZERO, DVec3::ONE);
        }
        // A margin so that no triangle lies on the grid's faces.
        let pad = (hi - lo).max_element().max(f64::MIN_POSITIVE) * 1e-6;
        let (lo, hi) = (lo - DVec3::splat(pad), hi + DVec3::splat(pad));
        let size = hi - lo;
        let side = (size.x * size.y * size.z
            / (CELLS_PER_TRIANGLE * triangles.len().max(1) as f64))
            .cbrt()
            .max(size.max_element() / MAX_CELLS_PER_AXIS as f64);
        let dims = [size.x, size.y, size.z]
            .map(|s| ((s / side).ceil() as usize).clamp(1, MAX_CELLS_PER_AXIS));
        let cell = size / DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64);
        let mut grid = Self {
            lo,
            hi,
            cell,
            dims,
            starts: Vec::new(),
            items: Vec::new(),
            triangles,
        };
        grid.fill(pad);
        grid
    }

    /// Lists each triangle in every cell its box, padded by `pad`, touches.
    fn fill(&mut self, pad: f64) {
        let ranges: Vec<[std::ops::RangeInclusive<usize>; 3]> = self
            .triangles
            .iter()
            .map(|(tri, _)| {
                let lo = tri[0].min(tri[1]).min(tri[2]) - DVec3::splat(pad);
                let hi = tri[0].max(tri[1]).max(tri[2]) + DVec3::splat(pad);
                let (a, b) = (self.cell_of(lo), self.cell_of(hi));
                [a[0]..=b[0], a[1]..=b[1], a[2]..=b[2]]
            })
            .collect();
        let cells = self.dims.iter().product::<usize>();
        let mut counts = vec![0u32; cells + 1];
        for r in &ranges {
            self.for_cells(r, |k| counts[k + 1] += 1);
        }
        for k in 0..cells {
            counts[k + 1] += counts[k];
        }
        let mut next = counts.clone();
        let mut items = vec![0u32; counts[cells] as usize];
        for (t, r) in ranges.iter().enumerate() {
            self.for_cells(r, |k| {
                items[next[k] as usize] = t as u32;
                next[k] += 1;
            });
        }
        self.starts = counts;
        self.items = items;
    }

    fn for_cells(&self, r: &[std::ops::RangeInclusive<usize>; 3], mut f: impl FnMut(usize)) {
        for z in r[2].clone() {
            for y in r[1].clone() {
                for x in r[0].clone() {
                    f(self.index([x, y, z]));
                }
            }
        }
    }

    fn index(&self, [x, y, z]: [usize; 3]) -> usize {
        (z * self.dims[1] + y) * self.dims[0] + x
    }

    /// The cell holding `p`, clamped to the grid.
    fn cell_of(&self, p: DVec3) -> [usize; 3] {
        let q = (p - self.lo) / self.cell;
        let at = |v: f64, d: usize| (v.floor().max(0.0) as usize).min(d - 1);
        [
            at(q.x, self.dims[0]),
            at(q.y, self.dims[1]),
            at(q.z, self.dims[2]),
        ]
    }

    /// `D(p, c)`: the weighted crossings of the segment from `p` to `c` (`0 < t < 1`).
    pub(crate) fn count(&self, p: DVec3, c: DVec3) -> i64 {
        let d = c - p;
        // The segment's stretch inside the grid (slabs).
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for k in 0..3 {
            if d[k] == 0.0 {
                if p[k] < self.lo[k] || p[k] > self.hi[k] {
                    return 0;
                }
                continue;
            }
            let (a, b) = ((self.lo[k] - p[k]) / d[k], (self.hi[k] - p[k]) / d[k]);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
        if !(t0 < t1) {
            return 0;
        }
        let mut cell = self.cell_of(p + d * t0);
        // Amanatides-Woo: the parameter of the next cell boundary on each axis.
        let mut step = [0isize; 3];
        let (mut t_max, mut t_delta) = ([f64::INFINITY; 3], [f64::INFINITY; 3]);
        for k in 0..3 {
            if d[k] > 0.0 {
                step[k] = 1;
                let edge = self.lo[k] + (cell[k] + 1) as f64 * self.cell[k];
                t_max[k] = (edge - p[k]) / d[k];
                t_delta[k] = self.cell[k] / d[k];
            } else if d[k] < 0.0 {
                step[k] = -1;
                let edge = self.lo[k] + cell[k] as f64 * self.cell[k];
                t_max[k] = (edge - p[k]) / d[k];
                t_delta[k] = -self.cell[k] / d[k];
            }
        }
        let mut total = 0i64;
        let mut t_enter = f64::NEG_INFINITY;
        loop {
            let axis = (0..3)
                .min_by(|&a, &b| t_max[a].total_cmp(&t_max[b]))
                .unwrap_or(0);
            let t_exit = if t_max[axis] >= t1 {
                f64::INFINITY
            } else {
                t_max[axis]
            };
            let k = self.index(cell);
            for &i in &self.items[self.starts[k] as usize..self.starts[k + 1] as usize] {
                let ([a, b, cc], w) = self.triangles[i as usize];
                if let Some(t) = ray_triangle_t(p, d, a, b, cc, 1.0)
                    && t >= t_enter
                    && t < t_exit
                {
                    total += w;
                }
            }
            if t_exit == f64::INFINITY {
                return total;
            }
            let next = cell[axis] as isize + step[axis];
            if next < 0 || next >= self.dims[axis] as isize {
                return total;
            }
            cell[axis] = next as usize;
            t_enter = t_exit;
            t_max[axis] += t_delta[axis];
        }
    }
}

/// The integration constant of every active receiver (0 for the rest): its crossings from its
/// ray origin to the light centre `c`.
pub(crate) fn receiver_constants(
    scene: &dyn Scene,
    units: u32,
    sides: &Sides,
    c: Vec3,
    origins: &[Vec3],
    active: &[bool],
) -> Vec<i64> {
    let grid = CrossingGrid::new(scene, units, sides, c);
    let cd = c.as_dvec3();
    origins
        .par_iter()
        .zip(active)
        .map(|(o, a)| if *a { grid.count(o.as_dvec3(), cd) } else { 0 })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stages::constant::{eye_constant, integration_constants};
    use crate::stages::edges::{Sides, Silhouettes, scene_edges, silhouettes};
    use crate::stages::light_shape::LightShape;
    use shadow_core::offset::RayOffset;
    use shadow_core::prelude::*;

    /// On built-in scenes (open and closed meshes, a room around the light, semi-opaque
    /// faces), each receiver's constant from the grid equals the brute-force count over every
    /// triangle, and the camera path's shadow-volume constant at the same origin.
    #[test]
    fn receiver_constants_equal_brute_force_and_the_shadow_volume_step() {
        for name in ["bunny", "contact", "semi-opaque", "cornell-box", "grass"] {
            let setup = shadow_scenes::builtin(name).unwrap();
            let scene = setup.scene.as_ref();
            let light = setup.lights[0].as_ref();
            let view = ViewSamples::render(scene, &setup.camera_or_default(), 48, 36).unwrap();
            let shape = LightShape::new(light, "test").unwrap();
            let one_sided = Sides::new(scene, &shape);
            let (edges, units) = scene_edges(scene, &one_sided);
            let sil = silhouettes(&edges, &shape, Silhouettes::Accurate);
            let offset = RayOffset::for_light(light);
            let origins: Vec<Vec3> = (0..view.len())
                .map(|i| {
                    view.get(i).map_or(Vec3::ZERO, |s| {
                        offset.offset(s.position, s.geometric_normal)
                    })
                })
                .collect();
            let valid = view.valid_mask();
            let got = receiver_constants(scene, units, &one_sided, shape.center, &origins, &valid);
            let c = shape.center.as_dvec3();
            let rule = CrossingRule::new(scene, units, &one_sided, c);
            let (eye, camera) = view.perspective().unwrap();
            let centred: Vec<Vec3> = origins
                .iter()
                .map(|o| (o.as_dvec3() - c).as_vec3())
                .collect();
            let eye_c = eye_constant(scene, units, &one_sided, eye, shape.center);
            let (volumes, _) = integration_constants(
                &edges,
                &sil,
                shape.center,
                eye,
                eye_c,
                camera,
                &origins,
                &centred,
                &valid,
            );
            let (mut checked, mut crossed, mut differ) = (0, 0, 0);
            for i in (0..view.len()).filter(|&i| valid[i]) {
                let o = origins[i].as_dvec3();
                let brute: i64 = (0..scene.triangle_count())
                    .filter_map(|t| {
                        let [a, b, cc] = scene.triangle(t).map(|v| v.as_dvec3());
                        ray_triangle_t(o, c - o, a, b, cc, 1.0).map(|_| rule.weight(t))
                    })
                    .sum();
                assert_eq!(got[i], brute, "{name} pixel {i}");
                differ += (got[i] != volumes[i]) as u32;
                checked += 1;
                crossed += (brute != 0) as u32;
            }
            assert!(checked > 500 && crossed > 20, "{name}: {checked} {crossed}");
            // A segment through an edge or vertex is counted by the ray test as it falls, by the
            // rasterizer's shared-edge rule exactly once: allow a few such pixels.
            assert!(
                differ * 500 <= checked,
                "{name}: {differ} of {checked} differ"
            );
        }
    }

    /// A segment that starts outside the grid, runs along a cell boundary or misses it counts
    /// what the brute force counts.
    #[test]
    fn segments_outside_and_along_cell_faces_count_like_brute_force() {
        let mut b = SceneBuilder::new();
        for k in 0..5 {
            let y = 0.5 + 0.3 * k as f32;
            b.push_mesh(MeshDesc::new(
                vec![
                    Vec3::new(-1.0, y, -1.0),
                    Vec3::new(1.0, y, -1.0),
                    Vec3::new(1.0, y, 1.0),
                    Vec3::new(-1.0, y, 1.0),
                ],
                vec![[0, 3, 2], [0, 2, 1]],
            ))
            .unwrap();
        }
        let scene = b.build().unwrap();
        let c = Vec3::new(0.1, 4.0, 0.2);
        let one_sided = Sides::closed_one_sided(&scene);
        let grid = CrossingGrid::new(&scene, 1, &one_sided, c);
        for p in [
            Vec3::new(0.3, 0.0, -0.2),
            Vec3::new(0.3, -5.0, -0.2),
            Vec3::new(5.0, 0.0, 5.0),
            Vec3::new(0.1, 0.0, 0.2),
            Vec3::new(0.0, 0.0, 0.0),
        ] {
            let (o, cd) = (p.as_dvec3(), c.as_dvec3());
            let brute = (0..scene.triangle_count())
                .filter(|&t| {
                    let [a, b, cc] = scene.triangle(t).map(|v| v.as_dvec3());
                    ray_triangle_t(o, cd - o, a, b, cc, 1.0).is_some()
                })
                .count() as i64;
            assert_eq!(grid.count(o, cd), brute, "{p}");
        }
        assert_eq!(grid.count(DVec3::new(0.3, 0.0, -0.2), c.as_dvec3()), 5);
    }
}
