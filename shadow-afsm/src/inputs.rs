//! What the passes take: the scene's triangles as casters in device buffers, view samples
//! grouped into receiver batches with their fitted frusta (section 4.3), and the edges that can
//! be a silhouette for some point of the light as degenerate casters for the stencil (section
//! 4.3).

use crate::frame::MapFrame;
use crate::params::{Caster, LightBounds, Receiver};
use crate::passes::{CasterBatch, device_error};
use glam::Vec3;
use shadow_core::gpu::{GpuContext, GpuError};
use shadow_core::prelude::*;

/// Receivers in batches of at most `per_batch`, each with its fitted frustum. When one
/// frustum cannot hold a batch (view samples all around an omni-directional light), the batch
/// is split by the cube face its samples lie toward, one frustum per face (each spans at most
/// 55 degrees from its axis).
pub(crate) fn group_receivers(
    center: Vec3,
    receivers: &[Receiver],
    pixels: &[usize],
    per_batch: usize,
    side: u32,
) -> Vec<(Vec<Receiver>, Vec<usize>, MapFrame)> {
    let mut out = Vec::new();
    for (chunk, px) in receivers.chunks(per_batch).zip(pixels.chunks(per_batch)) {
        let origins: Vec<Vec3> = chunk.iter().map(|r| r.origin()).collect();
        if let Ok(f) = MapFrame::fit(center, &origins, side) {
            out.push((chunk.to_vec(), px.to_vec(), f));
            continue;
        }
        let mut faces: [(Vec<Receiver>, Vec<usize>, Vec<Vec3>); 6] = Default::default();
        for ((r, &i), o) in chunk.iter().zip(px).zip(&origins) {
            let q = *o - center;
            let a = q.abs();
            let face = if a.x >= a.y && a.x >= a.z {
                (q.x < 0.0) as usize
            } else if a.y >= a.z {
                2 + (q.y < 0.0) as usize
            } else {
                4 + (q.z < 0.0) as usize
            };
            faces[face].0.push(*r);
            faces[face].1.push(i);
            faces[face].2.push(*o);
        }
        for (r, i, o) in faces {
            if r.is_empty() {
                continue;
            }
            // A cube face spans at most 54.7 degrees from its axis: the fit cannot fail for
            // points off the centre; points at the centre itself have no direction and are
            // fitted with the rest of their face.
            if let Ok(f) = MapFrame::fit(center, &o, side) {
                out.push((r, i, f));
            }
        }
    }
    out
}

/// The edges that can be a silhouette for some point of the light (section 4.3, after Laine et
/// al. 2005, the paper's \[LAA*05\]), as degenerate casters `(a, b, b)` whose influence
/// regions make the silhouette stencil. Boundary and non-manifold edges always count. A
/// manifold edge counts unless its faces' opacities agree and the whole light lies on the same
/// side of both faces (opposite sides when the faces disagree in orientation), where no light
/// point sees one face from the front and the other from the back.
pub fn silhouette_edges(scene: &dyn Scene, bounds: &LightBounds) -> Vec<Caster> {
    let topo = scene.topology();
    let positions = scene.positions();
    let indices = scene.triangles();
    // Which side of triangle t's plane the whole light lies on: 1 front, -1 back, 0 both.
    let side = |t: usize| -> i32 {
        let [a, b, c] = scene.triangle(t);
        let n = (b - a).cross(c - a);
        let (lo, hi) = bounds.range(n);
        let d = n.dot(a);
        if lo - d > 0.0 {
            1
        } else if hi - d < 0.0 {
            -1
        } else {
            0
        }
    };
    // Whether triangle t runs along edge (i, j) from i to j.
    let forward = |t: usize, i: u32, j: u32| {
        let tri = indices[t];
        (0..3).any(|k| tri[k] == i && tri[(k + 1) % 3] == j)
    };
    let mut out = Vec::new();
    for e in 0..topo.edge_count() {
        let [i, j] = topo.edge(e);
        let potential = match topo.faces(e) {
            &[f0, f1] => {
                let (f0, f1) = (f0 as usize, f1 as usize);
                let (s0, s1) = (side(f0), side(f1));
                let consistent = forward(f0, i, j) != forward(f1, i, j);
                // Transmittance also changes across an edge between different opacities.
                let opacities = scene.opacities();
                opacities[f0] != opacities[f1] || s0 == 0 || s1 == 0 || (s0 == s1) != consistent
            }
            _ => true,
        };
        if potential {
            let (a, b) = (positions[i as usize], positions[j as usize]);
            out.push(Caster::new([a, b, b], u32::MAX, false));
        }
    }
    out
}

/// How many closed meshes (components flagged in `closed`) separate `eye` from the light: hold
/// the one and not the other (`around_light`, per component)
/// ([`shadow_core::scene::components_containing`]).
pub(crate) fn closed_meshes_between(
    scene: &dyn Scene,
    closed: &[bool],
    around_light: &[bool],
    eye: Vec3,
) -> usize {
    shadow_core::scene::components_containing(scene, eye.as_dvec3(), closed)
        .iter()
        .zip(around_light)
        .filter(|(eye_in, light_in)| eye_in != light_in)
        .count()
}

/// The casters of `scene`: every triangle that hides anything (fully transparent ones are
/// left out), flagged closed when its component is in `closed`.
pub(crate) fn casters_of(scene: &dyn Scene, closed: &[bool]) -> Vec<Caster> {
    let topo = scene.topology();
    let opacities = scene.opacities();
    (0..scene.triangle_count())
        .filter(|&t| opacities[t] > 0.0)
        .map(|t| {
            Caster::new(scene.triangle(t), t as u32, closed[topo.component_of(t)])
                .with_opacity(opacities[t])
        })
        .collect()
}

/// `casters` in buffers of at most `per` casters each, with their penumbra volumes under the
/// light bounded by `light` (`volume.rs`; none for the stencil's edges, which the tile test
/// does not see).
pub(crate) fn upload_casters(
    gpu: &GpuContext,
    casters: &[Caster],
    light: Option<&LightBounds>,
    per: usize,
    label: &str,
) -> Result<Vec<CasterBatch>, TechniqueError> {
    casters
        .chunks(per)
        .map(|c| {
            let volumes = match light {
                Some(b) => crate::volume::volumes(c, b),
                None => vec![crate::volume::Volume::EVERYWHERE],
            };
            Ok(CasterBatch {
                buffer: gpu.storage(label, c)?,
                volumes: gpu.storage(label, &volumes)?,
                len: c.len() as u32,
            })
        })
        .collect::<Result<Vec<_>, GpuError>>()
        .map_err(device_error)
}
