//! The perspective camera: looks down its local -Z with +Y up (the glTF convention), vertical
//! field of view `yfov`; the image's own aspect ratio decides the horizontal extent.

use glam::{Affine3A, Vec3};
use thiserror::Error;

use crate::raster::{Projection, RasterView};

/// Why a camera could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CameraError {
    /// Position, target or transform is not finite.
    #[error("camera parameters are not finite")]
    NonFinite,
    /// Eye equals target, or up is parallel to the view direction.
    #[error("camera frame is degenerate: {0}")]
    Degenerate(&'static str),
    /// A near distance that is not positive and finite, or a far one not beyond it.
    #[error("clip distances near {near} and far {far:?} are not 0 < near < far < infinity")]
    ClipPlanes {
        /// The near distance.
        near: f32,
        /// The far distance.
        far: Option<f32>,
    },
    /// The field of view is outside (0, pi).
    #[error("vertical field of view {0} rad is outside (0, pi)")]
    FieldOfView(f32),
}

/// A perspective pinhole camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    world_from_camera: Affine3A,
    yfov: f32,
    znear: f32,
    /// The far clipping distance, when the camera has one (glTF's `zfar`): surfaces beyond it
    /// are not seen (they still cast shadows).
    zfar: Option<f32>,
}

impl Camera {
    /// A camera at `eye` looking at `target`, `up` roughly up, with vertical field of view `yfov`
    /// radians.
    ///
    /// # Errors
    /// [`CameraError`] for non-finite input, a degenerate frame or a bad field of view.
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, yfov: f32) -> Result<Self, CameraError> {
        if !(eye.is_finite() && target.is_finite() && up.is_finite()) {
            return Err(CameraError::NonFinite);
        }
        let forward = (target - eye)
            .try_normalize()
            .ok_or(CameraError::Degenerate("eye equals target"))?;
        let right = forward
            .cross(up)
            .try_normalize()
            .ok_or(CameraError::Degenerate(
                "up is parallel to the view direction",
            ))?;
        let true_up = right.cross(forward);
        let m = Affine3A::from_cols(right.into(), true_up.into(), (-forward).into(), eye.into());
        Self::from_world_transform(m, yfov)
    }

    /// A camera from its world transform (glTF node: -Z forward, +Y up; scale is removed).
    ///
    /// A mirroring transform (negative determinant) cannot be kept by a camera that does not
    /// mirror its image: its forward and up axes are kept and the right axis is made from them,
    /// so the image has the file's up and forward, and only a left-right mirror is lost.
    ///
    /// # Errors
    /// [`CameraError`] for a non-finite or singular transform or a bad field of view.
    pub fn from_world_transform(
        world_from_camera: Affine3A,
        yfov: f32,
    ) -> Result<Self, CameraError> {
        if !world_from_camera.is_finite() {
            return Err(CameraError::NonFinite);
        }
        if !(yfov > 0.0 && yfov < std::f32::consts::PI) {
            return Err(CameraError::FieldOfView(yfov));
        }
        // Orthonormalise (glTF cameras may carry scale).
        let axes = world_from_camera.matrix3;
        let z = Vec3::from(axes.z_axis)
            .try_normalize()
            .ok_or(CameraError::Degenerate("zero forward axis"))?;
        let (x, y) = if axes.determinant() < 0.0 {
            let y = Vec3::from(axes.y_axis)
                .reject_from_normalized(z)
                .try_normalize()
                .ok_or(CameraError::Degenerate("up axis parallel to forward"))?;
            (y.cross(z), y)
        } else {
            let x = Vec3::from(axes.x_axis)
                .reject_from_normalized(z)
                .try_normalize()
                .ok_or(CameraError::Degenerate("right axis parallel to forward"))?;
            (x, z.cross(x))
        };
        let m = Affine3A::from_cols(x.into(), y.into(), z.into(), world_from_camera.translation);
        Ok(Self {
            world_from_camera: m,
            yfov,
            znear: 1e-4,
            zfar: None,
        })
    }

    /// The near clipping distance.
    pub fn near(&self) -> f32 {
        self.znear
    }

    /// Sets the near clipping distance (default 1e-4 m).
    ///
    /// # Errors
    /// [`CameraError::ClipPlanes`] for a non-positive or non-finite distance, or one not
    /// before the far distance.
    pub fn with_near(mut self, znear: f32) -> Result<Self, CameraError> {
        if !(znear > 0.0 && znear.is_finite()) || self.zfar.is_some_and(|f| znear >= f) {
            return Err(CameraError::ClipPlanes {
                near: znear,
                far: self.zfar,
            });
        }
        self.znear = znear;
        Ok(self)
    }

    /// Camera position.
    pub fn position(&self) -> Vec3 {
        self.world_from_camera.translation.into()
    }
    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        -Vec3::from(self.world_from_camera.matrix3.z_axis)
    }
    /// Vertical field of view in radians.
    pub fn yfov(&self) -> f32 {
        self.yfov
    }
    /// The far clipping distance, if any.
    pub fn far(&self) -> Option<f32> {
        self.zfar
    }

    /// Sets the far clipping distance: [`crate::ViewSamples::render`] shows no surface beyond
    /// it (glTF's `zfar`; default none).
    ///
    /// # Errors
    /// [`CameraError::ClipPlanes`] for a distance that is not finite or not beyond the near one.
    pub fn with_far(mut self, zfar: f32) -> Result<Self, CameraError> {
        if !(zfar > self.znear && zfar.is_finite()) {
            return Err(CameraError::ClipPlanes {
                near: self.znear,
                far: Some(zfar),
            });
        }
        self.zfar = Some(zfar);
        Ok(self)
    }

    /// World from camera transform (rigid).
    pub fn world_from_camera(&self) -> Affine3A {
        self.world_from_camera
    }

    /// The rasterizer view for an image of `width x height` pixels.
    pub fn raster_view(&self, width: u32, height: u32) -> RasterView {
        let t = (0.5 * self.yfov).tan();
        let aspect = width.max(1) as f32 / height.max(1) as f32;
        RasterView {
            width,
            height,
            view_from_world: self.world_from_camera.inverse(),
            projection: Projection::Perspective {
                left: -t * aspect,
                right: t * aspect,
                bottom: -t,
                top: t,
                near: self.znear,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mirroring_camera_keeps_its_up_and_forward() {
        // A node looking down -Z with +Y up, mirrored left to right (scale -1 on X): the image
        // must stay the right way up (issue 69 item 3).
        let mirrored = Affine3A::from_scale(Vec3::new(-1.0, 1.0, 1.0));
        let cam = Camera::from_world_transform(mirrored, 0.8).unwrap();
        let m = cam.world_from_camera().matrix3;
        assert_eq!(Vec3::from(m.y_axis), Vec3::Y, "up");
        assert_eq!(Vec3::from(m.z_axis), Vec3::Z, "backward");
        assert_eq!(Vec3::from(m.x_axis), Vec3::X, "right, from up and forward");
        // Scaled but not mirrored: the right axis as given, as before.
        let scaled = Affine3A::from_scale(Vec3::new(2.0, 3.0, 0.5));
        let m = Camera::from_world_transform(scaled, 0.8)
            .unwrap()
            .world_from_camera()
            .matrix3;
        assert_eq!(
            [m.x_axis, m.y_axis, m.z_axis].map(Vec3::from),
            [Vec3::X, Vec3::Y, Vec3::Z]
        );
    }

    #[test]
    fn clip_distances_must_be_ordered() {
        let cam = Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 0.8).unwrap();
        assert_eq!(cam.with_far(5.0).unwrap().far(), Some(5.0));
        assert!(cam.with_far(1e-5).is_err());
        assert!(cam.with_far(f32::INFINITY).is_err());
        assert!(cam.with_far(5.0).unwrap().with_near(6.0).is_err());
    }
}
