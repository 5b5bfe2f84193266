//! glTF's default pose (glTF 2.0 sections 3.7.2.2 "Morph Targets" and 3.7.3 "Skins"): a
//! primitive's positions displaced by its morph targets at the node's (else the mesh's)
//! default weights, then moved by its skin's joints as the default scene places them. A
//! skinned primitive's own node transform is ignored, as the specification requires; only
//! the joints place it.

use glam::{Mat4, Vec3};
use gltf::Semantic;

use super::gltf_accessors::{read_joints, read_mat4, read_vec3, read_weights};
use super::{LoadError, LoadLimits};

/// The world matrix of every node of the scene's trees (`None` for nodes outside them).
/// A node reached twice keeps its first placement; the walk refuses such files by name.
pub(super) fn world_matrices(doc: &gltf::Document, roots: &[gltf::Node]) -> Vec<Option<Mat4>> {
    let mut world = vec![None; doc.nodes().len()];
    let mut stack: Vec<(gltf::Node, Mat4)> =
        roots.iter().map(|n| (n.clone(), Mat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        let Some(slot) = world.get_mut(node.index()) else {
            continue;
        };
        if slot.is_some() {
            continue;
        }
        let w = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        *slot = Some(w);
        stack.extend(node.children().map(|c| (c, w)));
    }
    world
}

/// `positions` displaced by the primitive's morph targets at `weights` (a target without a
/// weight has weight 0).
///
/// # Errors
/// [`LoadError::Accessor`] for a target whose position count differs from the primitive's.
pub(super) fn morph(
    buffers: &[Vec<u8>],
    prim: &gltf::Primitive,
    weights: &[f32],
    positions: &mut [Vec3],
    limits: &LoadLimits,
) -> Result<(), LoadError> {
    for (k, target) in prim.morph_targets().enumerate() {
        let w = weights.get(k).copied().unwrap_or(0.0);
        let Some(acc) = target.positions() else {
            continue;
        };
        if w == 0.0 {
            continue;
        }
        if !w.is_finite() {
            return Err(LoadError::Accessor(format!(
                "morph weight {k} is not finite"
            )));
        }
        let d = read_vec3(buffers, &acc, limits)?;
        if d.len() != positions.len() {
            return Err(LoadError::Accessor(format!(
                "morph target {k} has {} positions for {} vertices",
                d.len(),
                positions.len()
            )));
        }
        for (p, d) in positions.iter_mut().zip(d) {
            *p += w * d;
        }
    }
    Ok(())
}

/// `positions` moved by `skin`'s joints: each vertex by the weighted sum of its joints'
/// `world * inverse bind` matrices (every `JOINTS_n`/`WEIGHTS_n` set), into world space.
///
/// # Errors
/// [`LoadError::Accessor`] for missing or mismatched joint data, a joint index outside the
/// skin, or a joint outside the scene.
pub(super) fn skin(
    buffers: &[Vec<u8>],
    prim: &gltf::Primitive,
    skin: &gltf::Skin,
    world: &[Option<Mat4>],
    positions: &mut [Vec3],
    limits: &LoadLimits,
) -> Result<(), LoadError> {
    let bad = |why: String| LoadError::Accessor(format!("skin {}: {why}", skin.index()));
    let joints: Vec<gltf::Node> = skin.joints().collect();
    let inverse_bind = match skin.inverse_bind_matrices() {
        Some(acc) => read_mat4(buffers, &acc, limits)?,
        None => vec![Mat4::IDENTITY; joints.len()],
    };
    if inverse_bind.len() < joints.len() {
        return Err(bad(format!(
            "{} inverse bind matrices for {} joints",
            inverse_bind.len(),
            joints.len()
        )));
    }
    let matrices = joints
        .iter()
        .zip(&inverse_bind)
        .map(|(j, ibm)| {
            world
                .get(j.index())
                .copied()
                .flatten()
                .map(|w| w * *ibm)
                .ok_or_else(|| bad(format!("joint node {} is not in the scene", j.index())))
        })
        .collect::<Result<Vec<Mat4>, _>>()?;
    let mut blended = vec![Mat4::ZERO; positions.len()];
    let mut weight_sums = vec![0.0f32; positions.len()];
    let mut set = 0;
    while let (Some(ja), Some(wa)) = (
        prim.get(&Semantic::Joints(set)),
        prim.get(&Semantic::Weights(set)),
    ) {
        let (js, ws) = (
            read_joints(buffers, &ja, limits)?,
            read_weights(buffers, &wa, limits)?,
        );
        if js.len() != positions.len() || ws.len() != positions.len() {
            return Err(bad(format!("joint set {set} does not cover every vertex")));
        }
        for (((m, sum), j), w) in blended.iter_mut().zip(&mut weight_sums).zip(&js).zip(&ws) {
            *sum += w.iter().sum::<f32>();
            for k in 0..4 {
                if w[k] != 0.0 {
                    let joint = matrices.get(usize::from(j[k])).ok_or_else(|| {
                        bad(format!(
                            "joint index {} outside its {} joints",
                            j[k],
                            joints.len()
                        ))
                    })?;
                    *m += *joint * w[k];
                }
            }
        }
        set += 1;
    }
    if set == 0 {
        return Err(bad(
            "the skinned primitive has no JOINTS_0 and WEIGHTS_0".into()
        ));
    }
    if let Some(v) = weight_sums.iter().position(|s| !(*s > 0.0)) {
        return Err(bad(format!("vertex {v} has no joint weight")));
    }
    for (p, m) in positions.iter_mut().zip(&blended) {
        *p = m.transform_point3(*p);
    }
    Ok(())
}
