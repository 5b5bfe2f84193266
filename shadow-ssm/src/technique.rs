//! Shadow-map techniques: PCF and PCSS, the single-sample baselines a renderer would otherwise
//! pick (survey section 3.1.4 surveys the family), on the light-centre shadow map of GBP07
//! section 3.
//!
//! * **PCF** (percentage-closer filtering): the share of a fixed square of texels around the
//!   receiver's projection whose depth is not in front of the receiver.
//! * **PCSS** (percentage-closer soft shadows): a blocker search over the region that can hold
//!   the receiver's occluders (GBP07 eq. 1, shrunk with the min/max pyramid until it converges;
//!   a receiver with nothing in front of it in that region is lit at once), the mean depth `z_b`
//!   of the blockers found, then PCF over the penumbra width that eq. 1 gives for `z_b`.
//!
//! Both multiply by the exact fraction of the light above the receiver's tangent plane, the
//! part the reference can see at all. Depth comparisons are against the receiver's tangent
//! plane at each tap (receiver-plane depth bias, Isidoro 2006) plus one texel's footprint, so
//! wide kernels do not shadow a surface with itself. Wide kernels are
//! sampled on at most `MAX_TAPS x MAX_TAPS` evenly spaced texels. Receivers outside the frustum
//! (at or behind the light's plane) take the horizon fraction alone and are counted.

use glam::Vec3;
use rayon::prelude::*;
use serde_json::json;
use shadow_core::light::LightKind;
use shadow_core::offset::RayOffset;
use shadow_core::prelude::*;
use shadow_core::technique::{Capabilities, Processor, SceneRef};
use shadow_core::visibility::PixelClass;

use crate::backprojection::{Backprojection, LightOutline};
use crate::hierarchy::MinMaxPyramid;
use crate::light_frame::LightFrame;
use crate::shadow_map::ShadowMap;

/// Largest number of taps per side of a filter or search square.
pub const MAX_TAPS: u32 = 16;
/// Largest PCSS search or filter width, in texels.
pub const MAX_WIDTH: f64 = 256.0;
/// Largest back-projection kernel, in texels (the stride keeps its cost at `max_nspp`).
pub const MAX_KERNEL: f64 = 1024.0;

/// Which filter turns the shadow map into soft shadows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Filter {
    /// Fixed `(2 radius + 1)^2` texel PCF.
    Pcf {
        /// Kernel radius in texels.
        radius: u32,
    },
    /// Blocker search, then PCF of the width the blockers' mean depth gives.
    Pcss,
    /// Back-projection of the occluding samples onto the light (GBP06).
    Backprojection(Backprojection),
}

struct Prepared {
    scene: SceneRef,
    frame: LightFrame,
    offset: RayOffset,
    extent: f32,
}

/// PCF or PCSS on a light-centre shadow map.
pub struct ShadowMapFilter {
    name: String,
    filter: Filter,
    resolution: u32,
    peeling_layers: u32,
    prepared: Option<Prepared>,
}

impl std::fmt::Debug for ShadowMapFilter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShadowMapFilter")
            .field("name", &self.name)
            .field("filter", &self.filter)
            .field("resolution", &self.resolution)
            .finish()
    }
}

/// Visits `n x n` evenly spaced texels (depth and texel coordinates) over a square of side
/// `width` centred at `(x, y)`; returns `n * n`.
fn taps(sm: &ShadowMap, x: f64, y: f64, width: f64, mut visit: impl FnMut(f32, i64, i64)) -> u32 {
    let n = (width.ceil() as u32).clamp(1, MAX_TAPS);
    let step = width / n as f64;
    for j in 0..n {
        for i in 0..n {
            let tx = x - width * 0.5 + (i as f64 + 0.5) * step;
            let ty = y - width * 0.5 + (j as f64 + 0.5) * step;
            let (ix, iy) = (tx.floor() as i64, ty.floor() as i64);
            visit(sm.at(ix, iy), ix, iy);
        }
    }
    n * n
}

impl ShadowMapFilter {
    /// A technique with `filter` on a shadow map of `resolution` texels a side.
    pub fn new(name: &str, filter: Filter, resolution: u32) -> Self {
        Self {
            name: name.into(),
            filter,
            resolution,
            peeling_layers: 3,
            prepared: None,
        }
    }

    /// Shadow-map layers the filter reads.
    fn layers(&self) -> u32 {
        match self.filter {
            Filter::Backprojection(Backprojection {
                peeling_max_bias: Some(_),
                ..
            }) => self.peeling_layers,
            _ => 1,
        }
    }

    /// Sets the number of depth-peeled layers (BCS06 uses 3, the default).
    #[must_use]
    pub fn with_layers(mut self, layers: u32) -> Self {
        self.peeling_layers = layers.max(1);
        self
    }

    /// The unoccluded share seen by a receiver at texel `(x, y)`, depth `z`, whose tangent
    /// plane gives the depth `plane(ix, iy)` at each texel centre (receiver-plane depth bias:
    /// a tap occludes when its depth is in front of the receiver's plane there by more than
    /// `bias`, so wide kernels do not shadow a surface with itself).
    #[allow(clippy::too_many_arguments)]
    fn lit(
        &self,
        sm: &ShadowMap,
        pyramid: &MinMaxPyramid,
        outline: &LightOutline,
        frame: &LightFrame,
        x: f64,
        y: f64,
        z: f32,
        bias: f32,
        plane: &impl Fn(i64, i64) -> f32,
    ) -> f32 {
        let occludes = |d: f32, ix: i64, iy: i64| d < plane(ix, iy) - bias;
        let pcf = |width: f64| -> f32 {
            let mut lit = 0u32;
            let n = taps(sm, x, y, width, |d, ix, iy| {
                lit += !occludes(d, ix, iy) as u32
            });
            lit as f32 / n as f32
        };
        match self.filter {
            Filter::Pcf { radius } => {
                let r = radius as i64;
                let (cx, cy) = (x.floor() as i64, y.floor() as i64);
                let mut lit = 0u32;
                for j in -r..=r {
                    for i in -r..=r {
                        let (ix, iy) = (cx + i, cy + j);
                        lit += !occludes(sm.at(ix, iy), ix, iy) as u32;
                    }
                }
                lit as f32 / ((2 * r + 1) * (2 * r + 1)) as f32
            }
            Filter::Pcss => {
                // The search region: eq. 1, shrunk with the pyramid's local minimum until it
                // converges (GBP07 section 3); nothing in front of the receiver means lit.
                let (search, local_min) = pyramid.converged_kernel(sm, frame.width, x, y, z);
                if !(local_min < z - bias) {
                    return 1.0;
                }
                let search = search.clamp(1.0, MAX_WIDTH);
                let (mut sum, mut count) = (0.0f64, 0u32);
                taps(sm, x, y, search, |d, ix, iy| {
                    if occludes(d, ix, iy) {
                        sum += d as f64;
                        count += 1;
                    }
                });
                if count == 0 {
                    return 1.0;
                }
                let blocker = (sum / count as f64) as f32;
                pcf(sm
                    .kernel_width(frame.width, blocker, z)
                    .clamp(1.0, MAX_WIDTH))
            }
            Filter::Backprojection(bp) => {
                let (kernel, local_min) = pyramid.converged_kernel(sm, frame.width, x, y, z);
                if !(local_min < z - bias) {
                    return 1.0;
                }
                let kernel = kernel.clamp(1.0, MAX_KERNEL);
                let (occluded, _) = bp.occluded(sm, outline, x, y, z, kernel, &occludes);
                (1.0 - occluded).clamp(0.0, 1.0) as f32
            }
        }
    }
}

impl ShadowTechnique for ShadowMapFilter {
    fn name(&self) -> &str {
        &self.name
    }

    fn capabilities(&self) -> Capabilities {
        Capabilities {
            lights: vec![LightKind::Rectangle, LightKind::Disk, LightKind::Polygon],
            semi_opaque: false,
            textured_lights: false,
            needs_closed_meshes: false,
            sample_based: false,
            processor: Processor::Cpu,
        }
    }

    fn parameters(&self) -> serde_json::Value {
        json!({
            "filter": format!("{:?}", self.filter),
            "shadow_map_resolution": self.resolution,
        })
    }

    fn prepare(&mut self, scene: SceneRef, light: Light) -> Result<Stats, TechniqueError> {
        self.prepared = None;
        self.capabilities()
            .check(scene.as_ref(), light.as_ref())
            .map_err(|reason| TechniqueError::Unsupported {
                technique: self.name.clone(),
                reason,
            })?;
        let frame = LightFrame::new(light.as_ref(), &self.name)?;
        let extent = scene.bounds().union(light.bounds()).diagonal();
        self.prepared = Some(Prepared {
            scene,
            frame,
            offset: RayOffset::for_extent(extent),
            extent,
        });
        Ok(Stats::default())
    }

    fn estimate(&mut self, view: &ViewSamples) -> Result<Estimate, TechniqueError> {
        let p = self
            .prepared
            .as_ref()
            .ok_or_else(|| TechniqueError::NotPrepared(self.name.clone()))?;
        let mut stats = Stats::default();
        let n = view.len();
        let horizon: Vec<f32> = stats.time("horizon", || {
            (0..n)
                .into_par_iter()
                .map(|i| match view.get(i) {
                    Some(s) => p.frame.fraction_above(s.position, s.geometric_normal),
                    None => 0.0,
                })
                .collect()
        });
        let origins: Vec<Vec3> = (0..n)
            .map(|i| match view.get(i) {
                Some(s) => p.offset.offset(s.position, s.geometric_normal),
                None => Vec3::ZERO,
            })
            .collect();
        let receivers: Vec<Vec3> = (0..n)
            .filter(|&i| horizon[i] > 0.0)
            .map(|i| origins[i])
            .collect();
        let sm = stats.time("shadow-map", || {
            ShadowMap::render(
                p.scene.as_ref(),
                &p.frame,
                &receivers,
                self.resolution,
                self.layers(),
            )
        })?;
        let pyramid = stats.time("min-max-pyramid", || sm.as_ref().map(MinMaxPyramid::build));
        let outline = sm.as_ref().map(|m| {
            let pts: Vec<glam::Vec2> = p
                .frame
                .outline
                .iter()
                .map(|v| m.view.view_from_world.transform_point3(*v).truncate())
                .collect();
            LightOutline::new(&pts)
        });
        let w = view.width() as usize;
        struct Row {
            v: Vec<f32>,
            class: Vec<PixelClass>,
            outside: u64,
            facing_away: u64,
        }
        let rows: Vec<Row> = stats.time("filter", || {
            (0..view.height() as usize)
                .into_par_iter()
                .map(|row| {
                    let mut r = Row {
                        v: vec![0.0; w],
                        class: vec![PixelClass::Background; w],
                        outside: 0,
                        facing_away: 0,
                    };
                    for x in 0..w {
                        let i = row * w + x;
                        let Some(s) = view.get(i) else { continue };
                        let h = horizon[i];
                        if h == 0.0 {
                            r.facing_away += 1;
                            r.class[x] = PixelClass::Skipped;
                            continue;
                        }
                        let projected = sm
                            .as_ref()
                            .zip(pyramid.as_ref().zip(outline.as_ref()))
                            .and_then(|(m, h)| m.project(origins[i]).map(|q| (m, h, q)));
                        let lit = match projected {
                            None => {
                                r.outside += 1;
                                1.0
                            }
                            Some((m, h, (tx, ty, z))) => {
                                let plane = m.receiver_plane(origins[i], s.geometric_normal);
                                let texel = z / m.texels_per_unit as f32;
                                let bias = texel + 1e-6 * p.extent;
                                self.lit(m, h.0, h.1, &p.frame, tx, ty, z, bias, &plane)
                            }
                        };
                        let v = (lit * h).clamp(0.0, 1.0);
                        r.v[x] = v;
                        r.class[x] = if v >= 1.0 {
                            PixelClass::Lit
                        } else if v <= 0.0 {
                            PixelClass::Umbra
                        } else {
                            PixelClass::Penumbra
                        };
                    }
                    r
                })
                .collect()
        });
        let mut vis = VisibilityImage::scalar(view);
        let mut classes = Vec::with_capacity(n);
        let (mut outside, mut facing_away) = (0, 0);
        for (row, r) in rows.into_iter().enumerate() {
            vis.scalars_mut()[row * w..(row + 1) * w].copy_from_slice(&r.v);
            classes.extend(r.class);
            outside += r.outside;
            facing_away += r.facing_away;
        }
        vis.set_classes(classes)?;
        let counts = vis.class_counts().unwrap_or_default();
        stats.add("pixels-facing-away", facing_away);
        stats.add("pixels-outside-frustum", outside);
        stats.add("pixels-lit", counts[PixelClass::Lit as usize]);
        stats.add("pixels-umbra", counts[PixelClass::Umbra as usize]);
        stats.add("pixels-penumbra", counts[PixelClass::Penumbra as usize]);
        stats.add("shadow-map-texels", (self.resolution as u64).pow(2));
        vis.validate()?;
        Ok(Estimate {
            visibility: vis,
            stats,
        })
    }
}
