//! One estimate of a shadow-map filter, stage by stage (GBP07 sections 3 to 5): each
//! receiver's horizon and ray origin, the light-centre shadow map over the receivers above
//! their horizon, its min-max pyramid and the light's domain in the map's frame, screen-space
//! selection where configured, the filter over every receiver, then pull-push over the
//! receivers left to it.

use glam::Vec3;
use rayon::prelude::*;
use shadow_core::prelude::*;
use shadow_core::raster::RasterView;
use shadow_core::visibility::PixelClass;

use super::{Context, Counts, Outcome, Prepared, ShadowMapFilter};
use crate::contours::{MapFrame, Receiver, Scratch};
use crate::hierarchy::MinMaxPyramid;
use crate::light_domain::{LightDomain, RadianceTable};
use crate::light_view::MAX_OFF_AXIS_DEGREES;
use crate::screen_space;
use crate::shadow_map::ShadowMap;
use crate::statistics::{SsmCounter, SsmPhase};

/// Each receiver's share of the light above its tangent plane and its offset ray origin.
struct Receivers {
    horizon: Vec<f32>,
    origins: Vec<Vec3>,
}

/// How each receiver is seen: the camera (when there is one), whether it is a perspective
/// one, and its pixels per unit of image plane at unit depth.
#[derive(Clone, Copy)]
struct Eye<'v> {
    camera: Option<&'v RasterView>,
    perspective: bool,
    eta: f32,
    position: Option<Vec3>,
}

/// One row of filtered receivers.
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

impl Row {
    fn new(w: usize) -> Self {
        Self {
            v: vec![Vec3::ZERO; w],
            weight: vec![1.0; w],
            class: vec![PixelClass::Background; w],
            counts: Counts::default(),
            outside: 0,
            facing_away: 0,
            lit: 0,
            umbra: 0,
            reconstructed: 0,
        }
    }

    /// Appends `other` (the next row) to this one.
    fn append(&mut self, other: Row) {
        self.v.extend(other.v);
        self.weight.extend(other.weight);
        self.class.extend(other.class);
        self.counts.edges += other.counts.edges;
        self.counts.levels += other.counts.levels;
        self.counts.blended += other.counts.blended;
        self.counts.read += other.counts.read;
        self.outside += other.outside;
        self.facing_away += other.facing_away;
        self.lit += other.lit;
        self.umbra += other.umbra;
        self.reconstructed += other.reconstructed;
    }
}

/// What the filter of one receiver reads besides the receiver itself.
struct Filtering<'a> {
    p: &'a Prepared,
    context: Option<Context<'a>>,
    receivers: &'a Receivers,
    eye: Eye<'a>,
    textured: bool,
    /// The unshadowed value of a receiver: 1, or the light's mean radiance.
    mean_radiance: Vec3,
}

impl ShadowMapFilter {
    /// The estimate of `view` on prepared data `p`.
    pub(super) fn run(&self, p: &Prepared, view: &ViewSamples) -> Result<Estimate, TechniqueError> {
        let mut stats = Stats::default();
        let receivers = stats.time(SsmPhase::Horizon, || receivers(p, view));
        let sm = stats.time(SsmPhase::ShadowMap, || self.shadow_map(p, &receivers))?;
        let pyramid = stats.time(SsmPhase::MinMaxPyramid, || {
            sm.as_ref().map(MinMaxPyramid::build)
        });
        let textured = p.light.is_textured() && self.filter.integrates_the_light();
        let domain = sm.as_ref().map(|m| light_domain(p, m, textured));
        let mean_radiance = domain.as_ref().map_or(p.light.radiance().mean(), |d| {
            (d.full().radiance / d.area().max(f64::MIN_POSITIVE)).as_vec3()
        });
        let eye = self.eye(view)?;
        let selection = self.selection(view, eye, &mut stats);
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
        let filtering = Filtering {
            p,
            context,
            receivers: &receivers,
            eye,
            textured,
            mean_radiance,
        };
        let all = stats.time(SsmPhase::Filter, || {
            (0..view.height() as usize)
                .into_par_iter()
                .map_init(Scratch::default, |scratch, row| {
                    self.filter_row(&filtering, view, row, scratch)
                })
                .collect::<Vec<Row>>()
        });
        let mut rows = Row::new(0);
        for r in all {
            rows.append(r);
        }
        if rows.reconstructed > 0 {
            stats.time(SsmPhase::PullPush, || pull_push(view, &mut rows));
        }
        self.estimate(view, rows, textured, stats)
    }

    /// The light-centre shadow map over the receivers above their horizon; refused when they
    /// (or what can shadow them) reach further off the light's axis than one map holds.
    fn shadow_map(
        &self,
        p: &Prepared,
        receivers: &Receivers,
    ) -> Result<Option<ShadowMap>, TechniqueError> {
        let above: Vec<Vec3> = (0..receivers.horizon.len())
            .filter(|&i| receivers.horizon[i] > 0.0)
            .map(|i| receivers.origins[i])
            .collect();
        let sm = ShadowMap::render(
            p.scene.as_ref(),
            &p.frame,
            &above,
            self.resolution,
            self.layers(),
        )?;
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
        Ok(sm)
    }

    /// The view's camera, if any; screen-space selection refuses receivers without one.
    fn eye<'v>(&self, view: &'v ViewSamples) -> Result<Eye<'v>, TechniqueError> {
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
        Ok(Eye {
            camera,
            perspective,
            eta,
            position: view.eye(),
        })
    }

    /// Screen-space selection (GBP07 section 5, contours only): its pattern and the image's
    /// depth and normal discontinuities.
    #[allow(clippy::type_complexity)]
    fn selection(
        &self,
        view: &ViewSamples,
        eye: Eye,
        stats: &mut Stats,
    ) -> Option<(screen_space::ScreenSpace, Vec<f32>, Vec<bool>, f32)> {
        let (Some(s), super::Filter::Contours(_)) = (self.screen_space, self.filter) else {
            return None;
        };
        Some(stats.time(SsmPhase::Discontinuities, || {
            let spacing = s.pattern.clamp(2, 16).next_power_of_two() as usize;
            let disc = screen_space::discontinuities(
                view.width() as usize,
                view.height() as usize,
                &view.valid_mask(),
                view.depths(),
                view.geometric_normals(),
                2 * spacing,
            );
            (s, screen_space::pattern(s.pattern), disc, eye.eta)
        }))
    }

    /// The filter over one row of receivers.
    fn filter_row(
        &self,
        f: &Filtering,
        view: &ViewSamples,
        row: usize,
        scratch: &mut Scratch,
    ) -> Row {
        let w = view.width() as usize;
        let mut r = Row::new(w);
        for x in 0..w {
            let i = row * w + x;
            let Some(s) = view.get(i) else { continue };
            let h = f.receivers.horizon[i];
            if h == 0.0 {
                r.facing_away += 1;
                r.class[x] = PixelClass::Skipped;
                continue;
            }
            let origin = f.receivers.origins[i];
            let projected = f
                .context
                .as_ref()
                .and_then(|cx| cx.sm.project(origin).map(|q| (cx, q)));
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
                        plane: cx.sm.inverse_plane(origin, s.geometric_normal),
                        bias: texel + 1e-6 * f.p.extent,
                    };
                    let to_eye = match (f.eye.position, f.eye.camera) {
                        (Some(e), _) => (e - s.position).normalize_or_zero(),
                        (None, Some(c)) => c.view_from_world.inverse().transform_vector3(Vec3::Z),
                        (None, None) => s.geometric_normal,
                    };
                    let z_pe = if f.eye.perspective { s.depth } else { 1.0 };
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
                    (1.0, f.mean_radiance)
                }
                Outcome::Umbra => {
                    r.umbra += 1;
                    (0.0, Vec3::ZERO)
                }
                Outcome::Integrated(c) => (c.area as f32, c.radiance.as_vec3()),
                Outcome::Fraction(fr) => (fr as f32, f.mean_radiance * fr as f32),
                Outcome::Reconstruct => {
                    r.reconstructed += 1;
                    r.weight[x] = 0.0;
                    r.class[x] = PixelClass::Skipped;
                    continue;
                }
            };
            let v = (frac * h).clamp(0.0, 1.0);
            r.v[x] = if f.textured {
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
    }

    /// The visibility buffer from the filtered rows, with the counts of what was skipped.
    fn estimate(
        &self,
        view: &ViewSamples,
        rows: Row,
        textured: bool,
        mut stats: Stats,
    ) -> Result<Estimate, TechniqueError> {
        let mut vis = if textured {
            let mut vis = VisibilityImage::rgb_buffer(view);
            vis.rgbs_mut().copy_from_slice(&rows.v);
            vis
        } else {
            let mut vis = VisibilityImage::scalar(view);
            for (d, v) in vis.scalars_mut().iter_mut().zip(&rows.v) {
                *d = v.x.clamp(0.0, 1.0);
            }
            vis
        };
        vis.set_classes(rows.class)?;
        let by_class = vis.class_counts().unwrap_or_default();
        stats.add(SsmCounter::PixelsFacingAway, rows.facing_away);
        stats.add(SsmCounter::PixelsOutsideFrustum, rows.outside);
        stats.add(SsmCounter::PixelsSkippedLit, rows.lit);
        stats.add(SsmCounter::PixelsSkippedUmbra, rows.umbra);
        stats.add(SsmCounter::PixelsReconstructed, rows.reconstructed);
        stats.add(SsmCounter::PixelsLit, by_class[PixelClass::Lit as usize]);
        stats.add(
            SsmCounter::PixelsUmbra,
            by_class[PixelClass::Umbra as usize],
        );
        stats.add(
            SsmCounter::PixelsPenumbra,
            by_class[PixelClass::Penumbra as usize],
        );
        stats.add(SsmCounter::ShadowMapTexels, (self.resolution as u64).pow(2));
        stats.add(SsmCounter::ContourEdges, rows.counts.edges);
        stats.add(SsmCounter::ContourLevels, rows.counts.levels);
        stats.add(SsmCounter::PixelsBlended, rows.counts.blended);
        stats.add(SsmCounter::SamplesRead, rows.counts.read);
        vis.validate()?;
        Ok(Estimate::new(vis, stats))
    }
}

/// Each receiver's horizon fraction and its ray origin, offset off its surface.
fn receivers(p: &Prepared, view: &ViewSamples) -> Receivers {
    let n = view.len();
    let horizon = (0..n)
        .into_par_iter()
        .map(|i| match view.get(i) {
            Some(s) => p.frame.fraction_above(s.position, s.geometric_normal),
            None => 0.0,
        })
        .collect();
    let origins = (0..n)
        .map(|i| match view.get(i) {
            Some(s) => p.offset.offset(s.position, s.geometric_normal),
            None => Vec3::ZERO,
        })
        .collect();
    Receivers { horizon, origins }
}

/// The light's outline in the shadow map's frame, with its radiance table when the light is
/// textured and the filter integrates it.
fn light_domain(p: &Prepared, m: &ShadowMap, textured: bool) -> LightDomain {
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
}

/// Pull-push (GBP07 section 5) over the receivers left to it; background pixels carry no
/// value and do not feed the reconstruction.
fn pull_push(view: &ViewSamples, rows: &mut Row) {
    let n = view.len();
    let mut flat: Vec<f32> = rows.v.iter().flat_map(|v| v.to_array()).collect();
    let wts: Vec<f32> = (0..n)
        .map(|i| {
            if view.is_valid(i) {
                rows.weight[i]
            } else {
                0.0
            }
        })
        .collect();
    screen_space::pull_push(
        view.width() as usize,
        view.height() as usize,
        3,
        &mut flat,
        &wts,
    );
    for (i, v) in rows.v.iter_mut().enumerate() {
        if view.is_valid(i) {
            *v = Vec3::from_slice(&flat[3 * i..3 * i + 3]).max(Vec3::ZERO);
        }
    }
}
