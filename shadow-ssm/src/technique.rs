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

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use serde_json::json;
use shadow_core::light::LightKind;
use shadow_core::offset::RayOffset;
use shadow_core::prelude::*;
use shadow_core::spatial_order::in_spatial_order;
use shadow_core::technique::{Capabilities, Processor, SceneRef};
use shadow_core::visibility::{Coefficients, PixelClass};

use crate::backprojection::Backprojection;
use crate::contours::{MapFrame, Receiver, Scratch};
use crate::hierarchy::MinMaxPyramid;
use crate::light_domain::{Covered, LightDomain, RadianceTable};
use crate::light_frame::LightFrame;
use crate::light_space::{self, Contours};
use crate::light_view::MAX_OFF_AXIS_DEGREES;
use crate::screen_space::{self, ScreenSpace};
use crate::shadow_map::ShadowMap;
use crate::statistics::{SsmCounter, SsmPhase};

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

impl ShadowMapFilter {
    /// The estimate of `view` on prepared data `p`.
    fn run(&self, p: &Prepared, view: &ViewSamples) -> Result<Estimate, TechniqueError> {
        let mut stats = Stats::default();
        let n = view.len();
        let horizon: Vec<f32> = stats.time(SsmPhase::Horizon, || {
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
        let sm = stats.time(SsmPhase::ShadowMap, || {
            ShadowMap::render(
                p.scene.as_ref(),
                &p.frame,
                &receivers,
                self.resolution,
                self.layers(),
            )
        })?;
        if let Some(m) = &sm {
            let reach = m.window.off_axis_degrees();
            if !(reach <= MAX_OFF_AXIS_DEGREES) {
                return Err(TechniqueError::unsupported(
                    &self.name,
                    UnsupportedReason::View(format!(
                        "the receivers and the surfaces that can shadow them reach {reach:.1} \
                         degrees off the light's axis; one light-centre shadow map (GBP07 \
                         section 3) holds at most {MAX_OFF_AXIS_DEGREES} (a room around the \
                         light, or a fixture around it, needs a sample-based technique)"
                    )),
                ));
            }
        }
        let pyramid = stats.time(SsmPhase::MinMaxPyramid, || {
            sm.as_ref().map(MinMaxPyramid::build)
        });
        let textured = p.light.is_textured() && self.filter.integrates_the_light();
        let domain = sm.as_ref().map(|m| {
            let view_from_world = &m.view.view_from_world;
            let pts: Vec<glam::Vec2> = p
                .frame
                .outline
                .iter()
                .map(|v| view_from_world.transform_point3(*v).truncate())
                .collect();
            let domain = LightDomain::new(&pts);
            let world_from_view = view_from_world.inverse();
            let table = textured
                .then(|| {
                    RadianceTable::new(
                        p.light.as_ref(),
                        world_from_view.transform_vector3(Vec3::X),
                        world_from_view.transform_vector3(Vec3::Y),
                    )
                })
                .flatten();
            match table {
                Some(t) => domain.with_texture(t),
                None => domain,
            }
        });
        // The unshadowed value of a receiver: 1, or the light's mean radiance.
        let mean_radiance = domain.as_ref().map_or(p.light.radiance().mean(), |d| {
            (d.full().radiance / d.area().max(f64::MIN_POSITIVE)).as_vec3()
        });
        let camera = view.raster_view();
        if camera.is_none() && self.screen_space.is_some() {
            return Err(TechniqueError::unsupported(
                &self.name,
                UnsupportedReason::View(
                    "screen-space adaptive selection (GBP07 section 5) works in the camera's \
                     image; these receivers have no camera"
                        .into(),
                ),
            ));
        }
        // Pixels per unit of image plane at unit depth (the screen-space selection's scale).
        let (perspective, eta) = camera.map_or((false, 1.0), |c| {
            let (l, r, _, _, _, perspective) = c.extents();
            (perspective, view.width() as f32 / (r - l))
        });
        let selection = match (self.screen_space, self.filter) {
            (Some(s), Filter::Contours(_)) => Some(stats.time(SsmPhase::Discontinuities, || {
                let spacing = s.pattern.clamp(2, 16).next_power_of_two() as usize;
                let disc = screen_space::discontinuities(
                    view.width() as usize,
                    view.height() as usize,
                    &view.valid_mask(),
                    view.depths(),
                    view.geometric_normals(),
                    2 * spacing,
                );
                (s, screen_space::pattern(s.pattern), disc, eta)
            })),
            _ => None,
        };
        let w = view.width() as usize;
        struct Row {
            v: Vec<Vec3>,
            weight: Vec<f32>,
            class: Vec<PixelClass>,
            counts: Counts,
            outside: u64,
            facing_away: u64,
            lit: u64,
            umbra: u64,
            reconstructed: u64,
        }
        let context =
            sm.as_ref()
                .zip(pyramid.as_ref().zip(domain.as_ref()))
                .map(|(m, (pyr, dom))| {
                    let (left, _, _, top, _, _) = m.view.extents();
                    Context {
                        sm: m,
                        pyramid: pyr,
                        domain: dom,
                        frame: &p.frame,
                        map_frame: MapFrame {
                            left: left as f64,
                            top: top as f64,
                            texels_per_unit: m.texels_per_unit,
                        },
                        selection,
                    }
                });
        let eye = view.eye();
        let rows: Vec<Row> = stats.time(SsmPhase::Filter, || {
            (0..view.height() as usize)
                .into_par_iter()
                .map_init(Scratch::default, |scratch, row| {
                    let mut r = Row {
                        v: vec![Vec3::ZERO; w],
                        weight: vec![1.0; w],
                        class: vec![PixelClass::Background; w],
                        counts: Counts::default(),
                        outside: 0,
                        facing_away: 0,
                        lit: 0,
                        umbra: 0,
                        reconstructed: 0,
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
                        let projected = context
                            .as_ref()
                            .and_then(|cx| cx.sm.project(origins[i]).map(|q| (cx, q)));
                        let outcome = match projected {
                            None => {
                                r.outside += 1;
                                Outcome::Lit
                            }
                            Some((cx, (tx, ty, z))) => {
                                let texel = z / cx.sm.texels_per_unit as f32;
                                let receiver = Receiver {
                                    x: tx,
                                    y: ty,
                                    z,
                                    plane: cx.sm.inverse_plane(origins[i], s.geometric_normal),
                                    bias: texel + 1e-6 * p.extent,
                                };
                                let to_eye = match (eye, camera) {
                                    (Some(e), _) => (e - s.position).normalize_or_zero(),
                                    (None, Some(c)) => {
                                        c.view_from_world.inverse().transform_vector3(Vec3::Z)
                                    }
                                    (None, None) => s.geometric_normal,
                                };
                                let z_pe = if perspective { s.depth } else { 1.0 };
                                self.shade(
                                    cx,
                                    &receiver,
                                    (x as u32, row as u32, i),
                                    (z_pe, s.geometric_normal.dot(to_eye)),
                                    scratch,
                                    &mut r.counts,
                                )
                            }
                        };
                        let (frac, rgb) = match outcome {
                            Outcome::Lit => {
                                r.lit += 1;
                                (1.0, mean_radiance)
                            }
                            Outcome::Umbra => {
                                r.umbra += 1;
                                (0.0, Vec3::ZERO)
                            }
                            Outcome::Integrated(c) => (c.area as f32, c.radiance.as_vec3()),
                            Outcome::Fraction(f) => (f as f32, mean_radiance * f as f32),
                            Outcome::Reconstruct => {
                                r.reconstructed += 1;
                                r.weight[x] = 0.0;
                                r.class[x] = PixelClass::Skipped;
                                continue;
                            }
                        };
                        let v = (frac * h).clamp(0.0, 1.0);
                        r.v[x] = if textured {
                            (rgb * h).max(Vec3::ZERO)
                        } else {
                            Vec3::splat(v)
                        };
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
        let mut values = Vec::with_capacity(n);
        let mut weights = Vec::with_capacity(n);
        let mut classes = Vec::with_capacity(n);
        let mut counts = Counts::default();
        let (mut outside, mut facing_away, mut lit, mut umbra, mut reconstructed) = (0, 0, 0, 0, 0);
        for r in rows {
            values.extend(r.v);
            weights.extend(r.weight);
            classes.extend(r.class);
            counts.edges += r.counts.edges;
            counts.levels += r.counts.levels;
            counts.blended += r.counts.blended;
            counts.read += r.counts.read;
            outside += r.outside;
            facing_away += r.facing_away;
            lit += r.lit;
            umbra += r.umbra;
            reconstructed += r.reconstructed;
        }
        if reconstructed > 0 {
            stats.time(SsmPhase::PullPush, || {
                let mut flat: Vec<f32> = values.iter().flat_map(|v| v.to_array()).collect();
                // Background pixels carry no value: they must not feed the reconstruction.
                let wts: Vec<f32> = (0..n)
                    .map(|i| if view.is_valid(i) { weights[i] } else { 0.0 })
                    .collect();
                screen_space::pull_push(w, view.height() as usize, 3, &mut flat, &wts);
                for (i, v) in values.iter_mut().enumerate() {
                    if view.is_valid(i) {
                        *v = Vec3::from_slice(&flat[3 * i..3 * i + 3]).max(Vec3::ZERO);
                    }
                }
            });
        }
        let mut vis = if textured {
            let mut vis = VisibilityImage::rgb_buffer(view);
            vis.rgbs_mut().copy_from_slice(&values);
            vis
        } else {
            let mut vis = VisibilityImage::scalar(view);
            for (d, v) in vis.scalars_mut().iter_mut().zip(&values) {
                *d = v.x.clamp(0.0, 1.0);
            }
            vis
        };
        if let Coefficients::Scalar(_) = vis.coefficients() {
            // Already clamped.
        }
        vis.set_classes(classes)?;
        let counts_by_class = vis.class_counts().unwrap_or_default();
        stats.add(SsmCounter::PixelsFacingAway, facing_away);
        stats.add(SsmCounter::PixelsOutsideFrustum, outside);
        stats.add(SsmCounter::PixelsSkippedLit, lit);
        stats.add(SsmCounter::PixelsSkippedUmbra, umbra);
        stats.add(SsmCounter::PixelsReconstructed, reconstructed);
        stats.add(
            SsmCounter::PixelsLit,
            counts_by_class[PixelClass::Lit as usize],
        );
        stats.add(
            SsmCounter::PixelsUmbra,
            counts_by_class[PixelClass::Umbra as usize],
        );
        stats.add(
            SsmCounter::PixelsPenumbra,
            counts_by_class[PixelClass::Penumbra as usize],
        );
        stats.add(SsmCounter::ShadowMapTexels, (self.resolution as u64).pow(2));
        stats.add(SsmCounter::ContourEdges, counts.edges);
        stats.add(SsmCounter::ContourLevels, counts.levels);
        stats.add(SsmCounter::PixelsBlended, counts.blended);
        stats.add(SsmCounter::SamplesRead, counts.read);
        vis.validate()?;
        Ok(Estimate::new(vis, stats))
    }
}
