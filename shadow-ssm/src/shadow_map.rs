//! The shadow map of soft shadow mapping (GBP07 section 3, Fig. 2a): the scene seen from the
//! light's centre through a perspective frustum whose near plane and borders are parallel to
//! the light, storing linear depth (distance from the light's plane along its axis).
//!
//! The frustum is fitted to the view samples that can see the light, widened so that every
//! occluder able to shadow them is inside ([`crate::light_view`]).

use std::sync::Arc;

use glam::{Vec2, Vec3};
use shadow_core::raster::{RasterError, RasterView, rasterize_depth};
use shadow_core::scene::Scene;

use crate::light_frame::LightFrame;
use crate::light_view::{LightView, Window};

/// A light-centre shadow map.
#[derive(Debug, Clone)]
pub struct ShadowMap {
    /// The light's frustum.
    pub view: RasterView,
    /// Linear depth per texel (infinite where nothing was drawn), row-major, row 0 on top.
    /// Shared, not copied, with level 0 of the min/max pyramid built on it.
    pub depth: Arc<Vec<f32>>,
    /// Texels per unit of unit-depth coordinates (`r / w_n * z_n` of GBP07 eq. 1).
    pub texels_per_unit: f64,
    /// Smallest depth stored (the top of GBP07's hierarchical shadow map).
    pub min_depth: f32,
    /// Depth-peeled layers (BCS06 section 4.1): `layers` depths per texel, nearest first,
    /// strictly increasing, infinite where the beam hits fewer surfaces; `depth` is layer 0.
    pub layers: u32,
    /// The layered depths, `layers` per texel; empty for one layer (the map is `depth`, held
    /// once).
    pub layered: Vec<f32>,
    /// The frustum's window at unit depth.
    pub window: Window,
}

impl ShadowMap {
    /// Renders the shadow map of `scene` for `frame` at `resolution` texels a side, fitted to
    /// `receivers` (world positions) and the surfaces that can shadow them
    /// ([`LightView::window`]). `None` when no receiver lies in front of the light.
    ///
    /// # Errors
    /// [`RasterError`] for an invalid resolution.
    pub fn render(
        scene: &dyn Scene,
        frame: &LightFrame,
        receivers: &[Vec3],
        resolution: u32,
        layers: u32,
    ) -> Result<Option<Self>, RasterError> {
        let light = LightView::new(scene, frame);
        let Some(window) = Self::window(scene, &light, receivers) else {
            return Ok(None);
        };
        let mut map = Self::render_view(scene, light.raster_view(window, resolution), layers)?;
        map.window = window;
        Ok(Some(map))
    }

    /// The window of the map for `receivers` (world positions) seen from `light`: their
    /// projections at unit depth widened to hold every surface that can shadow them
    /// ([`LightView::window`]); `None` when no receiver lies in front of the light.
    pub fn window(scene: &dyn Scene, light: &LightView, receivers: &[Vec3]) -> Option<Window> {
        let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        let mut deepest = 0.0f32;
        for p in receivers {
            let v = light.view_from_world.transform_point3(*p);
            let d = -v.z;
            if d > light.near {
                let q = Vec2::new(v.x / d, v.y / d);
                lo = lo.min(q);
                hi = hi.max(q);
                deepest = deepest.max(d);
            }
        }
        (lo.x <= hi.x).then(|| light.window(scene.triangles(), lo, hi, deepest))
    }

    /// Renders the map of `scene` through the square light-centre frustum `view`.
    ///
    /// # Errors
    /// [`RasterError`] for an invalid resolution.
    pub fn render_view(
        scene: &dyn Scene,
        view: RasterView,
        layers: u32,
    ) -> Result<Self, RasterError> {
        let resolution = view.width;
        let (left, right, bottom, top, _, _) = view.extents();
        let layers = layers.max(1);
        let layered = rasterize_depth(scene.positions(), scene.triangles(), &view, layers)?;
        let (first, layered) = if layers == 1 {
            (layered, Vec::new())
        } else {
            let first = (0..(resolution as usize * view.height as usize))
                .map(|i| layered[i * layers as usize])
                .collect();
            (first, layered)
        };
        let min_depth = first.iter().copied().fold(f32::INFINITY, f32::min);
        Ok(Self {
            depth: Arc::new(first),
            layers,
            layered,
            texels_per_unit: resolution as f64 / (right as f64 - left as f64),
            min_depth,
            window: Window {
                mid: Vec2::new(0.5 * (left + right), 0.5 * (bottom + top)),
                half: 0.5 * (right - left),
            },
            view,
        })
    }

    /// Texel coordinates (continuous, texel centres at `i + 0.5`) and linear depth of `p`, or
    /// `None` when `p` is not in front of the near plane.
    pub fn project(&self, p: Vec3) -> Option<(f64, f64, f32)> {
        let v = self.view.view_from_world.transform_point3(p);
        let d = -v.z;
        let (l, _, _, t, near, _) = self.view.extents();
        if !(d > near) {
            return None;
        }
        let x = (v.x / d - l) as f64 * self.texels_per_unit;
        let y = (t - v.y / d) as f64 * self.texels_per_unit;
        Some((x, y, d))
    }

    /// Depth of layer `k` of texel `(x, y)`, infinite outside the map.
    #[inline]
    pub fn layer_at(&self, x: i64, y: i64, k: u32) -> f32 {
        let r = self.view.width as i64;
        if x < 0 || y < 0 || x >= r || y >= r || k >= self.layers {
            f32::INFINITY
        } else if self.layers == 1 {
            self.depth[(y * r + x) as usize]
        } else {
            self.layered[(y * r + x) as usize * self.layers as usize + k as usize]
        }
    }

    /// Depth of texel `(x, y)`, infinite outside the map.
    #[inline]
    pub fn at(&self, x: i64, y: i64) -> f32 {
        let r = self.view.width as i64;
        if x < 0 || y < 0 || x >= r || y >= r {
            f32::INFINITY
        } else {
            self.depth[(y * r + x) as usize]
        }
    }

    /// The plane through `p` with normal `n` as an inverse depth linear in texel coordinates.
    pub fn inverse_plane(&self, p: Vec3, n: Vec3) -> InversePlane {
        let v = &self.view.view_from_world;
        let (pv, nv) = (
            v.transform_point3(p).as_dvec3(),
            v.transform_vector3(n).as_dvec3(),
        );
        let np = nv.dot(pv);
        let (l, _, _, t, _, _) = self.view.extents();
        let (l, t, tpu) = (l as f64, t as f64, self.texels_per_unit);
        if np == 0.0 || !np.is_finite() {
            return InversePlane::default();
        }
        // The ray through texel point (X, Y) at unit depth is (u, w, -1), u = l + X / tpu,
        // w = t - Y / tpu; it meets the plane at depth np / (nv.x u + nv.y w - nv.z).
        InversePlane {
            a: (nv.x * l + nv.y * t - nv.z) / np,
            b: nv.x / tpu / np,
            c: -nv.y / tpu / np,
        }
    }

    /// The depth of the plane through `p` with normal `n` at each texel centre (infinite where
    /// the ray through the texel does not meet the plane in front of the light).
    pub fn receiver_plane(&self, p: Vec3, n: Vec3) -> impl Fn(i64, i64) -> f32 + use<> {
        let plane = self.inverse_plane(p, n);
        move |ix: i64, iy: i64| plane.depth(ix as f64 + 0.5, iy as f64 + 0.5, 0.0)
    }

    /// Width in texels of the region holding the occluders of a receiver at depth `z_p` that
    /// lie at depth `z` or further (GBP07 eq. 1): `w_l r z_n / w_n (1/z - 1/z_p)`.
    pub fn kernel_width(&self, light_width: f32, z: f32, z_p: f32) -> f64 {
        light_width as f64 * self.texels_per_unit * (1.0 / z as f64 - 1.0 / z_p as f64).max(0.0)
    }
}

#[cfg(test)]
impl ShadowMap {
    /// A one-layer `r x r` map over unit-depth `[-1, 1]^2` at the identity view (tests).
    pub(crate) fn unit_square(r: u32, depth: Vec<f32>) -> Self {
        use glam::Affine3A;
        use shadow_core::raster::Projection;
        let min_depth = depth.iter().copied().fold(f32::INFINITY, f32::min);
        Self {
            view: RasterView {
                width: r,
                height: r,
                view_from_world: Affine3A::IDENTITY,
                projection: Projection::Perspective {
                    left: -1.0,
                    right: 1.0,
                    bottom: -1.0,
                    top: 1.0,
                    near: 0.1,
                },
            },
            depth: Arc::new(depth),
            texels_per_unit: r as f64 / 2.0,
            min_depth,
            layers: 1,
            layered: Vec::new(),
            window: Window {
                mid: Vec2::ZERO,
                half: 1.0,
            },
        }
    }
}

/// A plane's inverse depth along the shadow map's rays, `a + b X + c Y` at texel coordinates
/// `(X, Y)` (texel centres at `i + 0.5`); perspective makes it linear, so its extremes over a
/// block lie at the corners.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct InversePlane {
    /// Value at texel coordinates (0, 0).
    pub a: f64,
    /// Slope along X.
    pub b: f64,
    /// Slope along Y.
    pub c: f64,
}

impl InversePlane {
    /// The smallest depth of the plane over the square of half-side `half` texels centred at
    /// `(x, y)` (infinite where the plane lies behind the light or is missed).
    #[inline]
    pub fn depth(&self, x: f64, y: f64, half: f64) -> f32 {
        let inv = self.a + self.b * x + self.c * y + (self.b.abs() + self.c.abs()) * half;
        if inv > 0.0 {
            (1.0 / inv) as f32
        } else {
            f32::INFINITY
        }
    }
}
