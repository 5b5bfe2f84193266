//! glTF `KHR_lights_punctual` lights as area lights. A point or spot light has no area, and a
//! soft shadow needs one, so each gets a size: a point light becomes a sphere light and a spot
//! light a disk facing along its axis, both of radius [`PunctualLight::radius`] (by default
//! [`DEFAULT_RADIUS_SHARE`] of the scene's diagonal; `render --light-size` sets it). A
//! directional light becomes a disk facing the scene from [`DIRECTIONAL_DISTANCE`] diagonals
//! away whose radius subtends [`DIRECTIONAL_ANGLE_DEGREES`], the sun's angular radius. The
//! light's colour times its intensity is the radiance (photometric units are not converted:
//! visibility does not depend on them, direct light only scales). A spot light's cone is not
//! modelled (the disk emits over its whole front), and the loader's note says so.

use glam::{Mat4, Vec3};
use gltf::json::Root;
use shadow_core::light::{DiskLight, Light, Radiance, SphereLight};
use std::sync::Arc;

use super::LoadError;

/// A point or spot light's default radius, as a share of the scene's bounding diagonal.
pub const DEFAULT_RADIUS_SHARE: f32 = 0.01;
/// A directional light's distance from the scene's centre, in scene diagonals.
pub const DIRECTIONAL_DISTANCE: f32 = 100.0;
/// A directional light's angular radius (the sun's).
pub const DIRECTIONAL_ANGLE_DEGREES: f32 = 0.27;

/// The kind of a punctual light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PunctualKind {
    /// Emits in all directions from a point.
    Point,
    /// Emits into a cone along the node's `-Z` axis (outer cone angle in radians).
    Spot {
        /// Outer cone half-angle.
        outer_cone: f32,
    },
    /// Emits along the node's `-Z` axis from infinitely far away.
    Directional,
}

/// A `KHR_lights_punctual` light as the file places it, and where its area light sits in
/// [`super::SceneSetup::lights`].
#[derive(Debug, Clone, PartialEq)]
pub struct PunctualLight {
    /// The light's name, or `light N`.
    pub name: String,
    /// Its kind.
    pub kind: PunctualKind,
    /// World position (unused for directional lights).
    pub position: Vec3,
    /// World direction of emission (the node's `-Z`), unit.
    pub direction: Vec3,
    /// Colour times intensity.
    pub radiance: Vec3,
    /// Index of its area light in the scene's lights.
    pub light_index: usize,
    /// Radius of the area light (point and spot lights).
    pub radius: f32,
}

impl PunctualLight {
    /// The area light standing for this light with radius `radius` (point and spot lights) in
    /// a scene whose bounds have centre `centre` and diagonal `diagonal`, and a sentence saying
    /// what was made.
    ///
    /// # Errors
    /// [`LoadError::Light`] when the result is not a valid light (a zero radius or a negative
    /// intensity, say).
    pub fn area_light(
        &self,
        radius: f32,
        centre: Vec3,
        diagonal: f32,
    ) -> Result<(Light, String), LoadError> {
        let invalid = |source| LoadError::Light {
            mesh: format!("punctual light '{}'", self.name),
            source,
        };
        let radiance = Radiance::constant(self.radiance).map_err(invalid)?;
        Ok(match self.kind {
            PunctualKind::Point => (
                Arc::new(SphereLight::new(self.position, radius, radiance).map_err(invalid)?),
                format!("a sphere light of radius {radius}"),
            ),
            PunctualKind::Spot { outer_cone } => (
                Arc::new(
                    DiskLight::new(self.position, self.direction, radius, radiance)
                        .map_err(invalid)?,
                ),
                format!(
                    "a disk light of radius {radius} facing its axis (its {:.1} degree cone is \
                     not modelled: the disk lights its whole front)",
                    outer_cone.to_degrees()
                ),
            ),
            PunctualKind::Directional => {
                let distance = DIRECTIONAL_DISTANCE * diagonal;
                let r = distance * DIRECTIONAL_ANGLE_DEGREES.to_radians().tan();
                (
                    Arc::new(
                        DiskLight::new(
                            centre - self.direction * distance,
                            self.direction,
                            r,
                            radiance,
                        )
                        .map_err(invalid)?,
                    ),
                    format!(
                        "a disk light {distance} away of radius {r} \
                         ({DIRECTIONAL_ANGLE_DEGREES} degrees seen from the scene)"
                    ),
                )
            }
        })
    }
}

/// Checks every node's reference to a punctual light before `gltf` dereferences it (it
/// unwraps a missing light list or index).
pub(super) fn check_references(root: &Root) -> Result<(), LoadError> {
    let count = root
        .extensions
        .as_ref()
        .and_then(|e| e.khr_lights_punctual.as_ref())
        .map_or(0, |l| l.lights.len());
    for (n, node) in root.nodes.iter().enumerate() {
        if let Some(l) = node
            .extensions
            .as_ref()
            .and_then(|e| e.khr_lights_punctual.as_ref())
            && l.light.value() >= count
        {
            return Err(LoadError::Missing(format!(
                "punctual light {} (of node {n}; the file has {count})",
                l.light.value()
            )));
        }
    }
    Ok(())
}

/// The punctual light on `node` (index `n`) placed by `world`, if it has one; its radius and
/// light index are filled in by the caller.
pub(super) fn on_node(
    root: &Root,
    n: usize,
    world: Mat4,
) -> Result<Option<PunctualLight>, LoadError> {
    let Some(i) = root.nodes[n]
        .extensions
        .as_ref()
        .and_then(|e| e.khr_lights_punctual.as_ref())
        .map(|l| l.light.value())
    else {
        return Ok(None);
    };
    let Some(l) = root
        .extensions
        .as_ref()
        .and_then(|e| e.khr_lights_punctual.as_ref())
        .and_then(|p| p.lights.get(i))
    else {
        return Err(LoadError::Missing(format!(
            "punctual light {i} (of node {n})"
        )));
    };
    use gltf::json::extensions::scene::khr_lights_punctual::Type;
    use gltf::json::validation::Checked;
    let kind = match (&l.type_, &l.spot) {
        (Checked::Valid(Type::Point), _) => PunctualKind::Point,
        (Checked::Valid(Type::Directional), _) => PunctualKind::Directional,
        (Checked::Valid(Type::Spot), Some(s)) => PunctualKind::Spot {
            outer_cone: s.outer_cone_angle,
        },
        _ => {
            return Err(LoadError::Gltf(format!(
                "punctual light {i} has no valid type (a spot light needs its `spot` cone)"
            )));
        }
    };
    let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
    if direction == Vec3::ZERO && kind != PunctualKind::Point {
        return Err(LoadError::Gltf(format!(
            "node {n} scales its punctual light {i} to nothing: it has no direction"
        )));
    }
    Ok(Some(PunctualLight {
        name: l.name.clone().unwrap_or_else(|| format!("light {i}")),
        kind,
        position: world.transform_point3(Vec3::ZERO),
        direction,
        radiance: Vec3::from(l.color) * l.intensity,
        light_index: 0,
        radius: 0.0,
    }))
}
