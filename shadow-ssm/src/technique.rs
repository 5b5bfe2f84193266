//! Shadow-map techniques on the light-centre shadow map of GBP07 section 3: PCF and PCSS, the
//! single-sample baselines a renderer would otherwise pick (survey section 3.1.4 surveys the
//! family), back-projection (GBP06, with BCS06's depth peeling) and contours (GBP07 sections
//! 4 and 5, with light- and screen-space multi-resolution).
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
//!
//! Every receiver is first classified from the min/max pyramid over its converged kernel:
//! nothing in front of it means lit (`pixels-skipped-lit`); for back-projection and contours,
//! every sample in front means umbra (`pixels-skipped-umbra`, GBP06: the back-projections then
//! cover the light, the contours have no edge and hide the centre).
//! Only the rest is integrated; with screen-space selection some of those are left to pull-push
//! (`pixels-reconstructed`).

use glam::DVec3;
use serde_json::json;
use shadow_core::light::LightKind;
use shadow_core::offset::RayOffset;
use shadow_core::prelude::*;
use shadow_core::spatial_order::in_spatial_order;
use shadow_core::technique::{Capabilities, Processor, SceneRef};

use crate::backprojection::Backprojection;
use crate::contours::{MapFrame, Receiver, Scratch};
use crate::hierarchy::MinMaxPyramid;
use crate::light_domain::{Covered, LightDomain};
use crate::light_frame::LightFrame;
use crate::light_space::{self, Contours};
use crate::screen_space::{self, ScreenSpace};
use crate::shadow_map::ShadowMap;
use crate::statistics::SsmPhase;

mod pass;

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
    /// Contour edges integrated radially (GBP07 sections 4 and 5.1).
    Contours(Contours),
}

impl Filter {
    /// True when the filter integrates over the light's area (and so can weight by a texture).
    fn integrates_the_light(&self) -> bool {
        matches!(self, Self::Backprojection(_) | Self::Contours(_))
    }
}

struct Prepared {
    scene: SceneRef,
    light: Light,
    frame: LightFrame,
    offset: RayOffset,
    extent: f32,
}

/// A soft-shadow filter on a light-centre shadow map.
#[derive(Clone)]
pub struct ShadowMapFilter {
    name: String,
    filter: Filter,
    resolution: u32,
    peeling_layers: u32,
    screen_space: Option<ScreenSpace>,
}

/// A filter prepared for one scene and light.
struct PreparedFilter {
    config: ShadowMapFilter,
    p: Prepared,
    stats: Stats,
}

impl std::fmt::Debug for PreparedFilter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PreparedFilter")
            .field("config", &self.config)
            .finish_non_exhaustive()
    }
}

impl std::fmt::Debug for ShadowMapFilter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShadowMapFilter")
            .field("name", &self.name)
            .field("filter", &self.filter)
            .field("resolution", &self.resolution)
            .field("screen_space", &self.screen_space)
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

/// What the filter found at one receiver.
enum Outcome {
    /// Nothing in front of the receiver in its kernel.
    Lit,
    /// Every sample of the kernel in front (contours only).
    Umbra,
    /// Integrated: the unoccluded fraction of the light's area and radiance integral.
    Integrated(Covered),
    /// A single-sample filter's unoccluded fraction.
    Fraction(f64),
    /// Left to pull-push (screen-space selection).
    Reconstruct,
}

/// Everything shared by the receivers of one estimate.
struct Context<'a> {
    sm: &'a ShadowMap,
    pyramid: &'a MinMaxPyramid,
    domain: &'a LightDomain,
    frame: &'a LightFrame,
    map_frame: MapFrame,
    /// Screen-space selection: settings, pattern, discontinuity buffer, camera's pixels per unit.
    selection: Option<(ScreenSpace, Vec<f32>, Vec<bool>, f32)>,
}

/// Per-receiver counters.
#[derive(Default)]
struct Counts {
    edges: u64,
    levels: u64,
    blended: u64,
    read: u64,
}

impl ShadowMapFilter {
    /// A technique with `filter` on a shadow map of `resolution` texels a side.
    pub fn new(name: &str, filter: Filter, resolution: u32) -> Self {
        Self {
            name: name.into(),
            filter,
            resolution,
            peeling_layers: 3,
            screen_space: None,
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

    /// Adds screen-space selection and pull-push (GBP07 section 5.2); it applies to the
    /// contour filter, whose classification gives the occluder depth it needs.
    #[must_use]
    pub fn with_screen_space(mut self, s: ScreenSpace) -> Self {
        self.screen_space = Some(s);
        self
    }

    /// The filter's outcome for a receiver at texel `(x, y)`, depth `z`, whose tangent plane
    /// gives the depth `plane(ix, iy)` at each texel centre (receiver-plane depth bias: a tap
    /// occludes when its depth is in front of the receiver's plane there by more than `bias`,
    /// so wide kernels do not shadow a surface with itself).
    fn shade(
        &self,
        cx: &Context,
        r: &Receiver,
        pixel: (u32, u32, usize),
        camera: (f32, f32),
        scratch: &mut Scratch,
        counts: &mut Counts,
    ) -> Outcome {
        let (sm, pyramid, frame) = (cx.sm, cx.pyramid, cx.frame);
        let (x, y, z, bias) = (r.x, r.y, r.z, r.bias);
        let plane = |ix: i64, iy: i64| r.plane.depth(ix as f64 + 0.5, iy as f64 + 0.5, 0.0);
        let occludes = |d: f32, ix: i64, iy: i64| d < plane(ix, iy) - bias;
        let pcf = |width: f64| -> f64 {
            let mut lit = 0u32;
            let n = taps(sm, x, y, width, |d, ix, iy| {
                lit += !occludes(d, ix, iy) as u32
            });
            lit as f64 / n as f64
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
                Outcome::Fraction(lit as f64 / ((2 * r + 1) * (2 * r + 1)) as f64)
            }
            Filter::Pcss => {
                // The search region: eq. 1, shrunk with the pyramid's local minimum until it
                // converges (GBP07 section 3); nothing in front of the receiver means lit.
                let (search, local_min) = pyramid.converged_kernel(sm, frame.width, x, y, z);
                if !(local_min < z - bias) {
                    return Outcome::Lit;
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
                    return Outcome::Lit;
                }
                let blocker = (sum / count as f64) as f32;
                Outcome::Fraction(pcf(sm
                    .kernel_width(frame.width, blocker, z)
                    .clamp(1.0, MAX_WIDTH)))
            }
            Filter::Backprojection(bp) => {
                let (kernel, local_min) = pyramid.converged_kernel(sm, frame.width, x, y, z);
                if !(local_min < z - bias) {
                    return Outcome::Lit;
                }
                let kernel = kernel.clamp(1.0, MAX_KERNEL);
                if umbra(sm, pyramid, r, kernel) {
                    return Outcome::Umbra;
                }
                let (occluded, read) = bp.occluded(sm, cx.domain, x, y, z, kernel, &occludes);
                counts.read += read;
                Outcome::Integrated(unoccluded(cx.domain, occluded))
            }
            Filter::Contours(c) => {
                let (kernel, local_min) = pyramid.converged_kernel(sm, frame.width, x, y, z);
                if !(local_min < z - bias) {
                    return Outcome::Lit;
                }
                let kernel = kernel.max(1.0);
                if umbra(sm, pyramid, r, kernel) {
                    return Outcome::Umbra;
                }
                let z_occ = light_space::occluder_depth(pyramid, kernel, x, y, z);
                if let Some((s, pattern, disc, eta)) = &cx.selection {
                    let (z_pe, n_dot_v) = camera;
                    let s_scr =
                        screen_space::penumbra_pixels(frame.width, z, z_occ, z_pe, n_dot_v, *eta);
                    if !disc[pixel.2] && !s.selected(pattern, pixel.0, pixel.1, s_scr) {
                        return Outcome::Reconstruct;
                    }
                }
                let lambda = c.lambda(sm, frame.width, z_occ, z);
                let (occluded, work) = c.occluded(
                    pyramid,
                    &cx.map_frame,
                    r,
                    kernel,
                    lambda,
                    cx.domain,
                    scratch,
                );
                counts.edges += work.edges;
                counts.levels += work.levels;
                counts.blended += (work.levels > 1) as u64;
                Outcome::Integrated(unoccluded(cx.domain, occluded))
            }
        }
    }
}

/// GBP06's umbra test from the kernel's depth bounds: every sample of the kernel (and its
/// one-texel border, which contour blocks read) lies in front of the receiver's plane, so the
/// samples' back-projections cover the light and contours find no edge.
fn umbra(sm: &ShadowMap, pyramid: &MinMaxPyramid, r: &Receiver, kernel: f64) -> bool {
    let h = 0.5 * kernel;
    let (x0, y0, x1, y1) = (
        (r.x - h).floor() as i64 - 1,
        (r.y - h).floor() as i64 - 1,
        (r.x + h).floor() as i64 + 1,
        (r.y + h).floor() as i64 + 1,
    );
    let inside_map = x0 >= 0 && y0 >= 0 && x1 < sm.view.width as i64 && y1 < sm.view.height as i64;
    inside_map
        && pyramid
            .bounds(x0, y0, x1, y1)
            .is_some_and(|(_, max)| max < r.plane.depth(r.x, r.y, h + 1.5) - r.bias)
}

/// The unoccluded part of the light, as fractions of its area: `(area, radiance / area)`.
fn unoccluded(domain: &LightDomain, occluded: Covered) -> Covered {
    let full = domain.full();
    let a = full.area.max(f64::MIN_POSITIVE);
    Covered {
        area: ((full.area - occluded.area) / a).clamp(0.0, 1.0),
        radiance: ((full.radiance - occluded.radiance) / a).max(DVec3::ZERO),
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
            textured_lights: self.filter.integrates_the_light(),
            needs_closed_meshes: false,
            sample_based: false,
            processor: Processor::Cpu,
            // GBP07's screen-space selection works in the camera's image.
            needs_camera: self.screen_space.is_some(),
        }
    }

    fn parameters(&self) -> serde_json::Value {
        json!({
            "filter": format!("{:?}", self.filter),
            "shadow_map_resolution": self.resolution,
            "screen_space": self.screen_space.map(|s| format!("{s:?}")),
        })
    }

    fn prepare(
        &self,
        scene: SceneRef,
        light: Light,
    ) -> Result<Box<dyn PreparedShadows>, TechniqueError> {
        self.capabilities()
            .require(&self.name, scene.as_ref(), light.as_ref())?;
        if light.is_textured() && light.kind() != LightKind::Rectangle {
            return Err(TechniqueError::unsupported(
                &self.name,
                UnsupportedReason::Light {
                    kind: light.kind(),
                    detail: Some("textured lights are integrated on rectangle lights only".into()),
                },
            ));
        }
        let mut stats = Stats::default();
        let frame = stats.time(SsmPhase::LightFrame, || {
            LightFrame::new(light.as_ref(), &self.name)
        })?;
        let extent = scene.bounds().union(light.bounds()).diagonal();
        let offset = RayOffset::for_light(&*light);
        Ok(Box::new(PreparedFilter {
            config: self.clone(),
            p: Prepared {
                scene,
                light,
                frame,
                offset,
                extent,
            },
            stats,
        }))
    }
}

impl PreparedShadows for PreparedFilter {
    fn name(&self) -> &str {
        &self.config.name
    }

    fn preparation(&self) -> &Stats {
        &self.stats
    }

    fn light(&self) -> &dyn AreaLight {
        self.p.light.as_ref()
    }

    fn check_outputs(&self, outputs: Outputs) -> Result<(), TechniqueError> {
        if outputs.direct {
            return Err(TechniqueError::no_direct_light(
                &self.config.name,
                "shadow-map filters",
            ));
        }
        Ok(())
    }

    /// A caller's points are shadowed in a spatial order, so that neighbouring receivers read
    /// neighbouring shadow-map texels ([`in_spatial_order`]).
    fn pass(&self, view: &ViewSamples, _outputs: Outputs) -> Result<Estimate, TechniqueError> {
        in_spatial_order(view, |v| self.config.run(&self.p, v))
    }
}
