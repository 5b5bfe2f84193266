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
        let z = Vec3::from(world_from_camera.matrix3.z_axis)
            .try_normalize()
            .ok_or(CameraError::Degenerate("zero forward axis"))?;
        let x = Vec3::from(world_from_camera.matrix3.x_axis)
            .reject_from_normalized(z)
            .try_normalize()
            .ok_or(CameraError::Degenerate("right axis parallel to forward"))?;
        let y = z.cross(x);
        let m = Affine3A::from_cols(x.into(), y.into(), z.into(), world_from_camera.translation);
        Ok(Self {
            world_from_camera: m,
            yfov,
            znear: 1e-4,
        })
    }

    /// The near clipping distance.
    pub fn near(&self) -> f32 {
        self.znear
    }

    /// Sets the near clipping distance (default 1e-4 m).
    ///
    /// # Errors
    /// [`CameraError::NonFinite`] for a non-positive or non-finite distance.
    pub fn with_near(mut self, znear: f32) -> Result<Self, CameraError> {
        if !(znear > 0.0 && znear.is_finite()) {
            return Err(CameraError::NonFinite);
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
