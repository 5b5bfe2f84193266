//! What `auto` looks with: the probe pass of the adaptive reference ([`shadow_ref::adaptive`]),
//! two independent 16-sample stratified sets per pixel of a low-resolution copy of the view,
//! evaluated either by the reference itself or by DCS on the same samples.
//!
//! DCS (Forest et al. 2008) agrees with the reference sample by sample on opaque occluders, so
//! on the same two sets both probes measure the same thing: which pixels are shadowed, which
//! lie in penumbra, and the variance of a 16-sample estimate. What differs is what the look
//! leaves behind. The reference's probe needs its BVH (10 to 90 ms on meshes of 13k to 124k
//! triangles on a 2-core machine), which only a reference configuration then uses; DCS's
//! preparation (edges, silhouettes, wedges) is the one every DCS configuration shares
//! ([`shadow_dcs::Dcs::prepare_sharing`]), and DCS is what `auto` picks on most opaque meshes.
//! So `auto` looks with DCS wherever DCS's answer is the reference's (opaque occluders, a light
//! DCS takes) and its look is the cheaper one, and with the reference elsewhere (semi-opaque
//! occluders: DCS sums opacities, section 3, where the reference multiplies transmittances;
//! lights DCS does not take; scenes with more than [`DCS_PROBE_SILHOUETTES_PER_TRIANGLE`]
//! silhouette edges a triangle, where DCS's preparation and frame, about 0.5 us a triangle and
//! 3 us a silhouette edge on the 2-core fitting machine, cost more than the reference's BVH,
//! about 1.3 us a triangle: `grass`'s single-sided blades make every edge a silhouette, and
//! DCS's look took 0.40 s there against the reference's 0.09 s; every mesh of the corpus share
//! is below 0.35). Each look has its own fitted cost ([`super::AutoModel::speed_ratio`]).

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use shadow_core::prelude::*;
use shadow_dcs::{Dcs, PreparedDcs};
use shadow_ref::AdaptiveReference;
use shadow_ref::adaptive::{DEFAULT_BATCH, DEFAULT_CAP, PreparedAdaptive};

use super::Features;

/// Which technique evaluated the probe's samples.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ProbeKind {
    /// The adaptive reference's probe pass (its BVH, beams, the two sets).
    #[default]
    Reference,
    /// DCS on the same two sets.
    Dcs,
}

/// A prepared probe.
pub(super) struct Probe {
    looker: Looker,
    /// Edges that are silhouettes from the light's centre ([`Features::silhouettes`]).
    silhouettes: usize,
}

/// What evaluates the probe's samples.
enum Looker {
    /// The adaptive reference, whose BVH the reference configurations then share.
    Reference(Box<PreparedAdaptive>),
    /// DCS on each of the two sets, the second sharing the first's preparation; the DCS
    /// configurations share it too.
    Dcs(Box<[PreparedDcs; 2]>),
}

/// Silhouette edges (from the light's centre) per triangle up to which `auto` looks with DCS;
/// above it, DCS's preparation and frame cost more than the reference's BVH (the module docs).
pub const DCS_PROBE_SILHOUETTES_PER_TRIANGLE: f64 = 0.5;

/// What the probe pass finds over a view (the fields of [`Features`] it sets).
#[derive(Debug, Clone, Copy, Default)]
struct Look {
    pixels: usize,
    shadowed: usize,
    penumbra: usize,
    mean_variance: f64,
}

/// The adaptive reference whose probe pass `auto` looks with (its sets are DCS's too).
pub(super) fn probe_reference(seed: u64) -> Result<AdaptiveReference, TechniqueError> {
    AdaptiveReference::new(0.01, DEFAULT_BATCH, DEFAULT_CAP, seed ^ 0xa070)
}

impl Probe {
    /// The probe for `scene` lit by `light`: DCS where its samples' answers are the
    /// reference's and its look is predicted to cost less ([`Probe::choose`]), else the
    /// reference.
    ///
    /// # Errors
    /// The preparation's error.
    pub(super) fn prepare(
        scene: SceneRef,
        light: Light,
        seed: u64,
    ) -> Result<Self, TechniqueError> {
        let silhouettes = silhouettes(scene.as_ref(), light.center());
        let kind = Self::choose(scene.as_ref(), light.as_ref(), silhouettes);
        Self::look_with(kind, scene, light, seed, silhouettes)
    }

    /// The probe of `kind` (see [`Probe::look_with`]).
    ///
    /// # Errors
    /// As [`Probe::look_with`].
    pub(super) fn prepare_kind(
        kind: ProbeKind,
        scene: SceneRef,
        light: Light,
        seed: u64,
    ) -> Result<Self, TechniqueError> {
        let silhouettes = silhouettes(scene.as_ref(), light.center());
        Self::look_with(kind, scene, light, seed, silhouettes)
    }

    /// Which probe looks at `scene` lit by `light`. DCS where it takes the scene and light,
    /// the occluders are opaque, and its look costs less than the reference's: the
    /// reference's is its BVH (about 1.3 us a triangle on the 2-core fitting machine), DCS's
    /// its preparation and frame (about 0.5 us a triangle and 3 us a silhouette edge), so DCS
    /// looks where silhouette edges (from the light's centre) are at most
    /// [`DCS_PROBE_SILHOUETTES_PER_TRIANGLE`] of the triangles: above the 0.27 where those
    /// rough costs cross, because DCS's preparation is also the chosen DCS configuration's, and
    /// far below `grass`'s 2. Measured on the 21 scenes of
    /// `cargo xtask budgets` (built-in and corpus): every mesh is below 0.35, while `grass`'s
    /// single-sided blades make every edge a silhouette (2 a triangle), where DCS's look took
    /// 0.40 s and the reference's 0.09 s.
    fn choose(scene: &dyn Scene, light: &dyn AreaLight, silhouettes: usize) -> ProbeKind {
        let dcs = Dcs::new(
            DEFAULT_BATCH,
            shadow_core::sampling::SamplingStrategy::Stratified,
            0,
        );
        let takes = dcs.is_ok_and(|d| d.capabilities().check(scene, light).is_ok());
        let few_silhouettes = silhouettes as f64
            <= DCS_PROBE_SILHOUETTES_PER_TRIANGLE * scene.triangle_count() as f64;
        if takes && !scene.has_semi_opaque() && few_silhouettes {
            ProbeKind::Dcs
        } else {
            ProbeKind::Reference
        }
    }

    /// The probe of `kind`, `silhouettes` the scene's count.
    ///
    /// # Errors
    /// The preparation's error; `Unsupported` for a DCS probe of a scene or light DCS does not
    /// take, `InvalidInput` for one of semi-opaque occluders (DCS's answer is not the
    /// reference's there).
    fn look_with(
        kind: ProbeKind,
        scene: SceneRef,
        light: Light,
        seed: u64,
        silhouettes: usize,
    ) -> Result<Self, TechniqueError> {
        let reference = probe_reference(seed)?;
        let looker = match kind {
            ProbeKind::Reference => {
                Looker::Reference(Box::new(reference.prepare_adaptive(scene, light)?))
            }
            ProbeKind::Dcs => {
                if scene.has_semi_opaque() {
                    return Err(TechniqueError::InvalidInput(
                        "a DCS probe of semi-opaque occluders: DCS sums opacities where the \
                         reference multiplies transmittances"
                            .into(),
                    ));
                }
                let [first, replicate] = reference.probe_samplers();
                let a = Dcs::with_sampler(first.clone())
                    .named("auto-probe-dcs")
                    .prepare_dcs(scene, light)?;
                let b = Dcs::with_sampler(replicate.clone())
                    .named("auto-probe-dcs")
                    .prepare_sharing(&a)?;
                Looker::Dcs(Box::new([a, b]))
            }
        };
        Ok(Self {
            looker,
            silhouettes,
        })
    }

    /// Which probe this is.
    pub(super) fn kind(&self) -> ProbeKind {
        match self.looker {
            Looker::Reference(_) => ProbeKind::Reference,
            Looker::Dcs(_) => ProbeKind::Dcs,
        }
    }

    /// The DCS preparation the DCS configurations share, when the probe is DCS.
    pub(super) fn dcs(&self) -> Option<&PreparedDcs> {
        match &self.looker {
            Looker::Dcs(d) => Some(&d[0]),
            Looker::Reference(_) => None,
        }
    }

    /// The reference's probe, when the probe is the reference.
    pub(super) fn reference(&self) -> Option<&PreparedAdaptive> {
        match &self.looker {
            Looker::Reference(r) => Some(r.as_ref()),
            Looker::Dcs(_) => None,
        }
    }

    /// The probe pass over `view`.
    fn look(&self, view: &ViewSamples, light: &dyn AreaLight) -> Result<Look, TechniqueError> {
        match &self.looker {
            Looker::Reference(r) => {
                let s = r.probe_view(view);
                Ok(Look {
                    pixels: s.pixels,
                    shadowed: s.shadowed,
                    penumbra: s.penumbra,
                    mean_variance: s.mean_variance,
                })
            }
            Looker::Dcs(d) => dcs_look(d, view, light),
        }
    }
}

/// The reference's probe statistics from DCS's per-sample visibility on the same two sets:
/// per pixel the two sets' means (radiance-weighted per channel under a textured light, as the
/// reference weighs them), the variance of one set's mean `(m0 - m1)^2 / 2` (largest channel),
/// and whether every sample was visible or none.
fn dcs_look(
    d: &[PreparedDcs; 2],
    view: &ViewSamples,
    light: &dyn AreaLight,
) -> Result<Look, TechniqueError> {
    // One frame for both sets: they differ only in their samples.
    let ests = d[0].estimate_replicates(&[&d[1]], view)?;
    let bits = |e: &Estimate| {
        e.visibility
            .per_sample()
            .cloned()
            .ok_or_else(|| TechniqueError::InvalidInput("DCS gave no per-sample visibility".into()))
    };
    let sets = [bits(&ests[0])?, bits(&ests[1])?];
    let samplers = [d[0].sampler(), d[1].sampler()];
    let textured = light.is_textured();
    let (mut units, mut radiances) = (Vec::new(), Vec::new());
    let mut look = Look::default();
    for i in 0..view.len() {
        let Some(s) = view.get(i) else { continue };
        look.pixels += 1;
        let (mut lit, mut dark) = (true, true);
        let mut means = [[0.0f64; 3]; 2];
        for (j, m) in means.iter_mut().enumerate() {
            let n = sets[j].samples();
            if textured {
                samplers[j].unit_samples(s.pixel, &mut units);
                radiances.clear();
                light.radiances_into(&units, &mut radiances);
            }
            for k in 0..n {
                let v = sets[j].visible(i, k);
                lit &= v;
                dark &= !v;
                if v {
                    let r = if textured {
                        radiances[k as usize].as_dvec3().to_array()
                    } else {
                        [1.0; 3]
                    };
                    for ch in 0..3 {
                        m[ch] += r[ch];
                    }
                }
            }
            *m = m.map(|x| x / f64::from(n));
        }
        look.shadowed += usize::from(!lit);
        look.penumbra += usize::from(!lit && !dark);
        look.mean_variance += (0..3)
            .map(|ch| 0.5 * (means[0][ch] - means[1][ch]).powi(2))
            .fold(0.0, f64::max);
    }
    look.mean_variance /= look.pixels.max(1) as f64;
    Ok(look)
}

/// The probe's features of `view` (see [`Features`]), `prepare` the seconds its preparation
/// took: the look on a copy of the view of at most `probe_pixels` pixels.
///
/// # Errors
/// The rasterization's or the probe pass's error.
pub(super) fn probe_features(
    probe: &Probe,
    scene: &dyn Scene,
    light: &dyn AreaLight,
    prepare: f64,
    view: &ViewSamples,
    probe_pixels: u32,
) -> Result<Features, TechniqueError> {
    let most = u64::from(probe_pixels.max(1));
    let (w, h) = (u64::from(view.width()), u64::from(view.height()));
    // The smallest integer reduction that fits the probe's pixel budget.
    let mut k = 1u64;
    while (w / k).max(1) * (h / k).max(1) > most {
        k += 1;
    }
    let t0 = std::time::Instant::now();
    // Every k-th view sample: the same surface points on the same camera rays, without
    // rasterizing the scene again.
    let small = view.every_kth(k as u32);
    // A view whose surfaces are too small for the reduced copy is probed at full size.
    let look = if small.valid_count() == 0 {
        probe.look(view, light)?
    } else {
        probe.look(&small, light)?
    };
    let pixels = look.pixels.max(1) as f64;
    // The pixels the reference must trace: the shadowed ones where its beam can prove the
    // rest lit (a light with a bounding quad), else every one.
    let beam = light.geometry().bounding_quad().is_some();
    Ok(Features {
        triangles: scene.triangle_count(),
        silhouettes: probe.silhouettes,
        semi_opaque: scene.has_semi_opaque(),
        pixels: view.valid_count(),
        sampled_share: if beam {
            look.shadowed as f64 / pixels
        } else {
            1.0
        },
        penumbra_share: look.penumbra as f64 / pixels,
        v16: look.mean_variance,
        probe_pixels: look.pixels,
        probe_seconds: prepare + t0.elapsed().as_secs_f64(),
        probe: probe.kind(),
    })
}

/// Edges of `scene` that are silhouettes seen from `c`: a boundary or non-manifold edge, or
/// one whose two faces lie on opposite sides of `c` (one faces it, the other does not).
fn silhouettes(scene: &dyn Scene, c: glam::Vec3) -> usize {
    let topo = scene.topology();
    let faces_c = |f: u32| {
        let [a, b, d] = scene.triangle(f as usize);
        (b - a).cross(d - a).dot(c - a) > 0.0
    };
    (0..topo.edge_count())
        .into_par_iter()
        .filter(|&e| match topo.faces(e) {
            [f0, f1] => faces_c(*f0) != faces_c(*f1),
            _ => true,
        })
        .count()
}
