//! Turning an emissive triangle mesh into an area light: planar meshes with one outline become
//! rectangle, disk or polygon lights (rectangles and disks recognised exactly), a closed mesh
//! whose vertices lie on a sphere becomes a sphere light, and any other shape (bent, with
//! holes, in pieces, double-sided, or textured in a way the exact shapes cannot map) becomes a
//! [`MeshLight`] (issue 52), which the reference and `ref-adaptive` render and the other
//! techniques refuse by name. Only a mesh with no area at all is an error.

use std::collections::HashMap;
use std::sync::Arc;

use glam::{Affine2, DVec3, Mat2, Vec2, Vec3};
use shadow_core::geometry::{Aabb, triangle_cross_f64};

use super::LoadError;
use shadow_core::light::{
    DiskLight, Light, LightError, MeshLight, PolygonLight, Radiance, RectLight, SphereLight,
    TexturedRadiance,
};

/// An emissive texture with the mesh's texture coordinates (per input vertex).
#[derive(Debug, Clone)]
pub struct EmissiveTexture {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Linear RGB texels, row 0 at texture v = 0.
    pub texels: Vec<Vec3>,
    /// Texture coordinates per input vertex.
    pub texcoords: Vec<Vec2>,
}

enum Shape {
    Rect(RectLight),
    Disk(DiskLight),
    Polygon(PolygonLight),
    Sphere(SphereLight),
}

/// Builds the light an emissive mesh describes (positions in world space): a rectangle,
/// disk or polygon for one flat outline, a sphere for a closed round mesh, else a mesh light.
///
/// # Errors
/// [`LoadError::Unsupported`] for a mesh without area and a texture without texture
/// coordinates; [`LoadError::Light`] when the light is invalid (a negative radiance).
pub fn light_from_emissive_mesh(
    name: &str,
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    emission: Vec3,
    texture: Option<EmissiveTexture>,
) -> Result<Light, LoadError> {
    let unsupported = |reason: &str| LoadError::Unsupported {
        mesh: name.to_string(),
        reason: reason.to_string(),
    };
    let light_err = light_error(name);
    if triangles.is_empty() {
        return Err(unsupported("emissive mesh has no triangles"));
    }
    let constant = Radiance::constant(emission).map_err(light_err)?;
    if let Some(v) = triangles
        .iter()
        .flatten()
        .copied()
        .find(|&v| !positions[v as usize].is_finite())
    {
        return Err(unsupported(&format!(
            "vertex {v} of the emissive mesh is not finite ({:?})",
            positions[v as usize]
        )));
    }
    // What emits: triangles with area and the vertices they use. A vertex no triangle uses or
    // a zero-area triangle (stitched strips have them) must not change the outline's shape.
    let mut texture = texture;
    let used = UsedGeometry::new(positions, triangles);
    if let Some(t) = texture
        .as_mut()
        .filter(|t| t.texcoords.len() == positions.len())
    {
        t.texcoords = used.old_index.iter().map(|&i| t.texcoords[i]).collect();
    }
    let (positions, triangles) = (used.positions.as_slice(), used.triangles.as_slice());
    if triangles.is_empty() {
        return Err(unsupported(
            "emissive mesh has no area: every triangle is degenerate",
        ));
    }
    let w = Welded::new(positions, triangles);
    if !(w.abs_area > 0.0) {
        return Err(unsupported(
            "emissive mesh has no area: every triangle is degenerate",
        ));
    }
    let as_mesh = |texture| mesh_light(name, positions, triangles, emission, texture);
    let shape = if w.planar() {
        planar_outline_shape(&w, constant.clone()).map_err(light_err)?
    } else if texture.is_none() {
        w.sphere(constant.clone()).map_err(light_err)?
    } else {
        None
    };
    // Holes, several pieces, a bent mesh, or one flat with triangles facing both ways (a
    // double-sided card emits from both sides, each triangle from its front): a mesh light.
    let Some(shape) = shape else {
        return as_mesh(texture);
    };
    let radiance = match texture {
        None => constant,
        Some(tex) => {
            if tex.texcoords.len() != positions.len() {
                return Err(unsupported("emissive texture without texture coordinates"));
            }
            let light_uv: Option<Vec<Vec2>> = positions.iter().map(|p| shape.uv_of(*p)).collect();
            let map = light_uv.and_then(|uv| fit_affine(triangles, &uv, &tex.texcoords));
            let Some(map) = map else {
                // Not one affine map over the exact shape: each triangle keeps its own.
                return as_mesh(Some(tex));
            };
            Radiance::Textured(
                TexturedRadiance::new(tex.width, tex.height, tex.texels, emission, map)
                    .map_err(light_err)?,
            )
        }
    };
    let light: Light = match shape {
        Shape::Rect(l) => Arc::new(l.with_radiance(radiance)),
        Shape::Disk(l) => Arc::new(l.with_radiance(radiance)),
        Shape::Polygon(l) => Arc::new(l.with_radiance(radiance)),
        Shape::Sphere(l) => Arc::new(l),
    };
    Ok(light)
}

impl Shape {
    /// Where `p` lies in the light's own texture coordinates; `None` on a sphere, which has
    /// none.
    fn uv_of(&self, p: Vec3) -> Option<Vec2> {
        match self {
            Shape::Rect(l) => Some(l.uv_of(p)),
            Shape::Disk(l) => Some(l.uv_of(p)),
            Shape::Polygon(l) => Some(l.uv_of(p)),
            Shape::Sphere(_) => None,
        }
    }
}

/// The mesh with exactly equal positions welded, and the sums its shape is read from.
/// The triangles of a mesh that have area and only the vertices they use, renumbered.
struct UsedGeometry {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// The input index of each kept vertex.
    old_index: Vec<usize>,
}

impl UsedGeometry {
    fn new(positions: &[Vec3], triangles: &[[u32; 3]]) -> Self {
        let mut new_index: Vec<Option<u32>> = vec![None; positions.len()];
        let mut out = Self {
            positions: Vec::new(),
            triangles: Vec::new(),
            old_index: Vec::new(),
        };
        for t in triangles {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            if triangle_cross_f64(a, b, c).length_squared() == 0.0 {
                continue;
            }
            let tri = t.map(|v| {
                *new_index[v as usize].get_or_insert_with(|| {
                    out.positions.push(positions[v as usize]);
                    out.old_index.push(v as usize);
                    (out.positions.len() - 1) as u32
                })
            });
            out.triangles.push(tri);
        }
        out
    }
}

struct Welded {
    positions: Vec<Vec3>,
    tris: Vec<[u32; 3]>,
    diag: f64,
    /// The sum of the triangles' area vectors.
    normal_sum: DVec3,
    /// The sum of their areas (twice).
    abs_area: f64,
    centroid: DVec3,
}

impl Welded {
    fn new(positions: &[Vec3], triangles: &[[u32; 3]]) -> Self {
        let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
        let mut welded: Vec<Vec3> = Vec::new();
        let remap: Vec<u32> = positions
            .iter()
            .map(|p| {
                let next = welded.len() as u32;
                *ids.entry(p.to_array().map(f32::to_bits))
                    .or_insert_with(|| {
                        welded.push(*p);
                        next
                    })
            })
            .collect();
        let tris: Vec<[u32; 3]> = triangles
            .iter()
            .map(|t| t.map(|v| remap[v as usize]))
            .collect();
        let diag = Aabb::from_points(&welded).diagonal() as f64;
        let mut normal_sum = DVec3::ZERO;
        let mut abs_area = 0.0;
        for t in &tris {
            let c = triangle_cross_f64(
                welded[t[0] as usize],
                welded[t[1] as usize],
                welded[t[2] as usize],
            );
            normal_sum += c;
            abs_area += c.length();
        }
        let centroid =
            welded.iter().fold(DVec3::ZERO, |a, p| a + p.as_dvec3()) / welded.len() as f64;
        Self {
            positions: welded,
            tris,
            diag,
            normal_sum,
            abs_area,
            centroid,
        }
    }

    fn cross(&self, t: &[u32; 3]) -> DVec3 {
        triangle_cross_f64(
            self.positions[t[0] as usize],
            self.positions[t[1] as usize],
            self.positions[t[2] as usize],
        )
    }

    /// Every triangle faces one way and every vertex lies in one plane.
    fn planar(&self) -> bool {
        self.normal_sum.length() > 0.999 * self.abs_area && {
            let nn = self.normal_sum.normalize();
            self.positions
                .iter()
                .all(|p| (p.as_dvec3() - self.centroid).dot(nn).abs() <= 1e-4 * self.diag)
        }
    }

    /// A sphere light for a closed mesh whose vertices all lie at one distance from their
    /// centroid; `None` for any other shape. A flat mesh whose faces cancel (double-sided, or
    /// wound both ways) is told from a round one by a plane through its largest triangle.
    fn sphere(&self, constant: Radiance) -> Result<Option<Shape>, LightError> {
        let closed = matches!(boundary_loops(&self.tris), Ok(l) if l.is_empty());
        let dists: Vec<f64> = self
            .positions
            .iter()
            .map(|p| (p.as_dvec3() - self.centroid).length())
            .collect();
        let r = dists.iter().sum::<f64>() / dists.len() as f64;
        let largest = self
            .tris
            .iter()
            .max_by(|a, b| self.cross(a).length().total_cmp(&self.cross(b).length()));
        let flat_both_ways = largest.is_some_and(|t| {
            let c = self.cross(t);
            c.length() > 0.0 && {
                let nn = c.normalize();
                let o = self.positions[t[0] as usize].as_dvec3();
                self.positions
                    .iter()
                    .all(|p| (p.as_dvec3() - o).dot(nn).abs() <= 1e-4 * self.diag)
            }
        });
        if !flat_both_ways
            && closed
            && self.positions.len() >= 6
            && dists.iter().all(|d| (d - r).abs() <= 2e-3 * r)
        {
            let sphere = SphereLight::new(self.centroid.as_vec3(), r as f32, constant)?;
            return Ok(Some(Shape::Sphere(sphere)));
        }
        Ok(None)
    }
}

/// The rectangle, disk or polygon a flat mesh's one boundary loop outlines; `None` for holes,
/// several pieces, a boundary touching itself or an outline no polygon light takes.
fn planar_outline_shape(w: &Welded, constant: Radiance) -> Result<Option<Shape>, LightError> {
    let normal = w.normal_sum.normalize().as_vec3();
    let outline = match boundary_loops(&w.tris) {
        Ok(loops) if loops.len() == 1 => simplify(
            &loops[0]
                .iter()
                .map(|&v| w.positions[v as usize])
                .collect::<Vec<_>>(),
        ),
        _ => return Ok(None),
    };
    match planar_shape(&outline, normal, constant) {
        Ok(shape) => Ok(Some(shape)),
        Err(LightError::InvalidPolygon(_)) => Ok(None),
        Err(e) => Err(e),
    }
}

/// The emissive mesh as a [`MeshLight`]: every triangle of area, in its winding, with its
/// texture coordinates when the emission is a texture.
fn mesh_light(
    name: &str,
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    emission: Vec3,
    texture: Option<EmissiveTexture>,
) -> Result<Light, LoadError> {
    let light_err = light_error(name);
    let tris: Vec<[Vec3; 3]> = triangles
        .iter()
        .map(|t| t.map(|v| positions[v as usize]))
        .collect();
    let light = match texture {
        None => MeshLight::new(
            &tris,
            None,
            Radiance::constant(emission).map_err(light_err)?,
        ),
        Some(tex) => {
            if tex.texcoords.len() != positions.len() {
                return Err(LoadError::Unsupported {
                    mesh: name.to_string(),
                    reason: "emissive texture without texture coordinates".into(),
                });
            }
            let tc: Vec<[Vec2; 3]> = triangles
                .iter()
                .map(|t| t.map(|v| tex.texcoords[v as usize]))
                .collect();
            let radiance = Radiance::Textured(
                TexturedRadiance::new(
                    tex.width,
                    tex.height,
                    tex.texels,
                    emission,
                    Affine2::IDENTITY,
                )
                .map_err(light_err)?,
            );
            MeshLight::new(&tris, Some(&tc), radiance)
        }
    }
    .map_err(light_err)?;
    Ok(Arc::new(light))
}

/// The error of an invalid light made from mesh `name`.
fn light_error(name: &str) -> impl Fn(LightError) -> LoadError + Copy + '_ {
    move |source| LoadError::Light {
        mesh: name.to_string(),
        source,
    }
}

/// Directed boundary loops (edges used by exactly one triangle), following the winding.
fn boundary_loops(tris: &[[u32; 3]]) -> Result<Vec<Vec<u32>>, String> {
    let mut count: HashMap<(u32, u32), i32> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let mut next: HashMap<u32, u32> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            match count[&(a.min(b), a.max(b))] {
                1 => {
                    if next.insert(a, b).is_some() {
                        return Err("boundary touches itself at a vertex".into());
                    }
                }
                2 => {}
                _ => return Err("non-manifold edge in an emissive mesh".into()),
            }
        }
    }
    let mut loops = Vec::new();
    let mut starts: Vec<u32> = next.keys().copied().collect();
    starts.sort_unstable();
    let mut used = std::collections::HashSet::new();
    for s in starts {
        if used.contains(&s) {
            continue;
        }
        let mut lp = vec![s];
        used.insert(s);
        let mut v = s;
        loop {
            let Some(&w) = next.get(&v) else {
                return Err("open boundary chain".into());
            };
            if w == s {
                break;
            }
            if !used.insert(w) || lp.len() > next.len() {
                return Err("boundary is not a simple loop".into());
            }
            lp.push(w);
            v = w;
        }
        loops.push(lp);
    }
    Ok(loops)
}

/// Removes vertices where the outline goes straight on.
fn simplify(outline: &[Vec3]) -> Vec<Vec3> {
    let n = outline.len();
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let (p, c, q) = (outline[(i + n - 1) % n], outline[i], outline[(i + 1) % n]);
        let (a, b) = ((c - p).as_dvec3(), (q - c).as_dvec3());
        if a.cross(b).length() > 1e-6 * a.length() * b.length() {
            out.push(c);
        }
    }
    out
}

fn planar_shape(outline: &[Vec3], normal: Vec3, radiance: Radiance) -> Result<Shape, LightError> {
    let n = outline.len();
    if n == 4 {
        let e: Vec<Vec3> = (0..4).map(|i| outline[(i + 1) % 4] - outline[i]).collect();
        let right = (0..4).all(|i| {
            e[i].dot(e[(i + 1) % 4]).abs() <= 1e-4 * e[i].length() * e[(i + 1) % 4].length()
        });
        if right {
            // Start at a corner so that edge 0 and edge 3 (reversed) span the rectangle with
            // u x v along the winding normal.
            let c0 = outline[0];
            let (u, v) = (0.5 * e[0], -0.5 * e[3]);
            let (u, v) = if u.cross(v).dot(normal) >= 0.0 {
                (u, v)
            } else {
                (v, u)
            };
            let center = c0 + u + v;
            return RectLight::new(center, u, v, radiance).map(Shape::Rect);
        }
    }
    let c = outline.iter().fold(Vec3::ZERO, |a, p| a + *p) / n as f32;
    let d: Vec<f32> = outline.iter().map(|p| (*p - c).length()).collect();
    let r = d.iter().sum::<f32>() / n as f32;
    if n >= 8 && d.iter().all(|x| (x - r).abs() <= 1e-3 * r) {
        return DiskLight::new(c, normal, r, radiance).map(Shape::Disk);
    }
    PolygonLight::new(outline.to_vec(), radiance).map(Shape::Polygon)
}

/// Fits `texcoord = M * light_uv + t` on the largest triangle and checks every vertex.
fn fit_affine(triangles: &[[u32; 3]], luv: &[Vec2], tc: &[Vec2]) -> Option<Affine2> {
    let best = triangles.iter().max_by(|a, b| {
        let area = |t: &[u32; 3]| {
            (luv[t[1] as usize] - luv[t[0] as usize])
                .perp_dot(luv[t[2] as usize] - luv[t[0] as usize])
                .abs()
        };
        area(a).total_cmp(&area(b))
    })?;
    let [a, b, c] = best.map(|v| v as usize);
    let l = Mat2::from_cols(luv[b] - luv[a], luv[c] - luv[a]);
    if l.determinant().abs() < 1e-12 {
        return None;
    }
    let t = Mat2::from_cols(tc[b] - tc[a], tc[c] - tc[a]);
    let m = t * l.inverse();
    let map = Affine2::from_mat2_translation(m, tc[a] - m * luv[a]);
    let ok = luv
        .iter()
        .zip(tc)
        .all(|(l, t)| (map.transform_point2(*l) - *t).length() <= 1e-3 * (1.0 + t.length()));
    (ok && map.is_finite()).then_some(map)
}
