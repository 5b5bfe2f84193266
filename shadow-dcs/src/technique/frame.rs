//! The frame of one estimate (Algorithm 2 for one light): preparation per scene and light,
//! the integration constants and counter width of every view sample, the squares of the wedge
//! scan, and the estimate and direct illumination assembled from the per-pixel pass
//! ([`super::pixel`]).

use super::output::{PixelOutput, record_counts};
use super::pixel::PixelPass;
use super::*;
use crate::statistics::{DcsCounter, DcsGauge, DcsPhase};

impl Dcs {
    /// Everything per frame before the per-pixel pass: the view samples' origins and horizons,
    /// the squares with their wedges and where each square's visibility comes from (the plan),
    /// and the integration constants of the pixels DCS estimates: from the eye's shadow
    /// volumes under a perspective camera, else per receiver along its own segment to the
    /// light centre ([`crate::stages::receiver_constant`]).
    pub(super) fn frame<'a, 'p>(
        &self,
        p: &'p Prepared,
        view: &'a ViewSamples,
        traceable: bool,
        stats: &mut Stats,
    ) -> Result<(Frame<'a>, Plan<'p>), TechniqueError> {
        let n = view.len();
        let (origins, horizon): (Vec<Vec3>, Vec<Horizon>) = (0..n)
            .into_par_iter()
            .map(|i| match view.get(i) {
                Some(s) => {
                    let o = p.offset.offset(s.position, s.geometric_normal);
                    (o, Self::horizon(&p.shape, &s, o))
                }
                None => (Vec3::ZERO, Horizon::Below),
            })
            .unzip();
        let active: Vec<bool> = horizon.par_iter().map(|h| *h != Horizon::Below).collect();
        let c = p.shape.center;
        let cd = c.as_dvec3();
        let centred: Vec<Vec3> = origins
            .par_iter()
            .map(|o| (o.as_dvec3() - cd).as_vec3())
            .collect();
        let planar_ok = match (&p.planar, self.covered) {
            (Some(pl), CoveredSamples::Exact) => centred
                .par_iter()
                .zip(&active)
                .map(|(x, a)| *a && x.dot(pl.normal).abs() > NEAR_PLANE * x.length())
                .collect(),
            _ => Vec::new(),
        };
        stats.add(DcsCounter::Wedges, p.scan.len() as u64);
        let mut f = Frame {
            origins,
            centred,
            horizon,
            active,
            constants: Vec::new(),
            planar_ok,
            bits: 0,
            view,
        };
        let plan = stats.time(DcsPhase::SquarePlan, || self.plan(p, &f, traceable));
        self.integration_constants(p, &mut f, &plan, view.perspective(), stats);
        Ok((f, plan))
    }

    /// The integration constant `D(p, c)` of every view sample (section 4.1: the shadow-volume
    /// step from the eye of a perspective `camera`, else each receiver's own crossings; none
    /// when `plan` traces the frame) and the counter width from the largest (section 5.3).
    fn integration_constants(
        &self,
        p: &Prepared,
        f: &mut Frame,
        plan: &Plan,
        camera: Option<(Vec3, &shadow_core::raster::RasterView)>,
        stats: &mut Stats,
    ) {
        let c = p.shape.center;
        if plan.reference.is_some() {
            // The frame is traced: no shadow volume is needed.
            stats.add(DcsCounter::ShadowVolumesSkipped, 1);
            f.constants = vec![0; f.active.len()];
            f.bits = self.forced_bits.unwrap_or_else(|| width_for(0));
            return;
        }
        let (origins, centred) = (&f.origins, &f.centred);
        let constants = match camera {
            Some((eye, camera)) => {
                let (constants, quads) = stats.time(DcsPhase::ShadowVolumes, || {
                    let eye_c = eye_constant(p.scene.as_ref(), p.units, &p.sides, eye, c);
                    integration_constants(
                        &p.edges,
                        &p.silhouettes,
                        c,
                        eye,
                        eye_c,
                        camera,
                        origins,
                        centred,
                        &f.active,
                    )
                });
                stats.add(DcsCounter::ShadowVolumeQuads, quads);
                constants
            }
            None => {
                let constants = stats.time(DcsPhase::ReceiverConstants, || {
                    receiver_constants(p.scene.as_ref(), p.units, &p.sides, c, origins, &f.active)
                });
                let counted = f.active.iter().filter(|a| **a).count();
                stats.add(DcsCounter::ReceiverConstantSegments, counted as u64);
                constants
            }
        };
        let max_constant = constants.par_iter().copied().max().unwrap_or(0).max(0) as u64;
        f.bits = self.forced_bits.unwrap_or_else(|| width_for(max_constant));
        f.constants = constants;
        stats.gauge_max(DcsGauge::MaxIntegrationConstant, max_constant);
        stats.gauge_max(DcsGauge::CounterBits, f.bits as u64);
    }

    /// Runs the per-pixel pass over the square of `job`: its wedge pairs (from the wedges its
    /// box keeps), then every view sample, handed to `visit` with its class and the scratch
    /// holding its visible samples and, with `values`, its samples' visibilities and depth
    /// complexities. A square the plan traces takes the same from shadow rays on the same
    /// samples instead (no depth complexities).
    #[expect(
        clippy::too_many_arguments,
        reason = "the per-pixel pass hands its prepared data, frame, pixel, scratch and counters down the hot path"
    )]
    pub(super) fn run_square(
        &self,
        p: &Prepared,
        f: &Frame,
        plan: &Plan,
        job: &Job,
        values: bool,
        counts: &mut Counts,
        buffers: &mut SquareBuffers,
        mut visit: impl FnMut(usize, &ViewSample, PixelClass, &Scratch),
    ) {
        let view = f.view;
        let SquareBuffers {
            pairs,
            scan,
            scratch,
        } = buffers;
        scratch.want_values = values;
        if let Some(reference) = plan.reference {
            counts.traced_squares += 1;
            let w = view.width();
            for i in job.rect.pixels(w) {
                let (x, y) = ((i % w as usize) as u32, (i / w as usize) as u32);
                let Some(s) = view.get_at(x, y) else { continue };
                let class = self.ray_pixel(p, reference, f, i, &s, scratch, counts);
                visit(i, &s, class, scratch);
            }
            return;
        }
        square_pairs(&Self::scan_input(p, f), &job.wedges, job.rect, pairs, scan);
        counts.scan.add(&pairs.counts);
        counts.pairs += pairs.len() as u64;
        let w = view.width() as usize;
        for (j, x, y) in pairs.pixels() {
            let i = y as usize * w + x as usize;
            let Some(s) = view.get_at(x, y) else { continue };
            let (entries, tests) = pairs.of(j);
            let class = PixelPass {
                dcs: self,
                p,
                f,
                i,
                s: &s,
                scratch,
                counts,
            }
            .run(entries, tests);
            visit(i, &s, class, scratch);
        }
    }

    /// What the wedge scan reads of a frame.
    pub(super) fn scan_input<'a>(p: &'a Prepared, f: &'a Frame) -> ScanInput<'a> {
        ScanInput {
            edges: &p.edges,
            wedges: &p.scan,
            lanes: &p.scan_lanes,
            c: p.shape.center.as_dvec3(),
            width: f.view.width(),
            origins: &f.origins,
            centred: &f.centred,
            active: &f.active,
            slack: (FOLD_SLACK * p.extent) as f32,
            planar: (!f.planar_ok.is_empty()).then_some((&p.centred_edges[..], &f.planar_ok[..])),
        }
    }

    /// The squares of the view with the wedges each keeps (the box hierarchy of
    /// [`crate::accel::bins`]: blocks, then their squares), and the number of (block, wedge)
    /// pairs kept.
    pub(super) fn square_lists(&self, p: &Prepared, f: &Frame) -> (Vec<(Rect, Vec<u32>)>, u64) {
        let view = f.view;
        let input = Self::scan_input(p, f);
        let blocks = crate::accel::bins::blocks(view.width(), view.height());
        let levels = BlockWedges::new(&input, &blocks);
        let lists: Vec<(Vec<Vec<u32>>, usize)> = blocks
            .par_iter()
            .enumerate()
            .map(|(bi, (_, squares))| levels.square_lists(&input, bi, squares))
            .collect();
        let kept = lists.iter().map(|(_, k)| *k as u64).sum();
        let jobs = blocks
            .iter()
            .zip(lists)
            .flat_map(|((_, squares), (l, _))| squares.iter().copied().zip(l))
            .collect();
        (jobs, kept)
    }

    /// Runs `work` on every square of `plan` in parallel (a block boundary is no barrier: every
    /// square of the view is one parallel loop, so a thread that runs out of work steals any
    /// square left, not only those of the block it is in). Returns each square's result.
    pub(super) fn squares<T: Send>(
        &self,
        plan: &Plan,
        work: impl Fn(&Job, &mut SquareBuffers) -> T + Sync + Send,
    ) -> Vec<(Rect, T)> {
        // One square per job: a square's cost ranges from nothing to milliseconds (the
        // penumbra gathers in a few of them), and rayon's own split of the list left one
        // thread on a run of 128 costly squares while the other idled (on `bunny`, a thread
        // busy 90 ms of the pass's 164 ms). The buffers go back to a pool after each square,
        // since a job per square would otherwise start from empty buffers every time.
        let pool = Mutex::new(Vec::<SquareBuffers>::new());
        plan.jobs
            .par_iter()
            .with_max_len(1)
            .map(|job| {
                let mut buffers = pool
                    .lock()
                    .ok()
                    .and_then(|mut p| p.pop())
                    .unwrap_or_default();
                let done = work(job, &mut buffers);
                if let Ok(mut p) = pool.lock() {
                    p.push(buffers);
                }
                (job.rect, done)
            })
            .collect()
    }

    /// Direct illumination of every view sample by DCS eq. 6: the light samples' contributions
    /// weighted by their binary visibility (saturated opacity sums with semi-opaque occluders).
    ///
    /// # Errors
    /// `Unsupported` for orthographic views.
    pub(super) fn direct(
        &self,
        p: &Prepared,
        view: &ViewSamples,
    ) -> Result<Vec<Vec3>, TechniqueError> {
        let mut stats = Stats::default();
        let (f, plan) = self.frame(p, view, true, &mut stats)?;
        let parts = self.squares(&plan, |job, buffers| {
            let mut out = Vec::with_capacity(job.rect.len());
            let mut counts = Counts::default();
            let mut units = Vec::new();
            let mut samples = Vec::new();
            // Eq. 6 weighs every sample by its visibility.
            self.run_square(
                p,
                &f,
                &plan,
                job,
                true,
                &mut counts,
                buffers,
                |i, s, _, scratch| {
                    let light = p.light.as_ref();
                    let samples: &[LightSample] = if scratch.samples.is_empty() {
                        self.sampler.unit_samples(s.pixel, &mut units);
                        samples.clear();
                        light.sample_into(&units, &mut samples);
                        &samples
                    } else {
                        &scratch.samples
                    };
                    let albedo = s.albedo_in(p.scene.as_ref());
                    let vis = &scratch.vis;
                    out.push((i, pixel_direct(s, albedo, light, samples, |k| vis[k])));
                },
            );
            out
        });
        let mut out = vec![Vec3::ZERO; view.len()];
        for (i, d) in parts.into_iter().flat_map(|(_, v)| v) {
            out[i] = d;
        }
        Ok(out)
    }

    /// Builds the edges, silhouettes, wedges and (section 7.3) tables for `scene` and `light`.
    ///
    /// # Errors
    /// [`TechniqueError::Unsupported`] when the scene or light is outside the capabilities.
    pub fn prepare_dcs(
        &self,
        scene: SceneRef,
        light: Light,
    ) -> Result<PreparedDcs, TechniqueError> {
        self.capabilities()
            .require(&self.name, scene.as_ref(), light.as_ref())?;
        let mut stats = Stats::default();
        let shape = LightShape::new(light.as_ref(), &self.name)?;
        let one_sided = Sides::new(scene.as_ref(), &shape);
        let (edges, units) =
            stats.time(DcsPhase::Edges, || scene_edges(scene.as_ref(), &one_sided));
        let sil = stats.time(DcsPhase::Silhouettes, || {
            silhouettes(&edges, &shape, self.detection)
        });
        stats.add(DcsCounter::Edges, edges.len() as u64);
        stats.add(DcsCounter::SilhouetteEdges, sil.len() as u64);
        stats.add(
            DcsCounter::ExplicitTriangles,
            one_sided.explicit_list.len() as u64,
        );
        let tables = match self.covered {
            CoveredSamples::Discrete | CoveredSamples::Refined => {
                Some(stats.time(DcsPhase::DiscreteTables, || {
                    DiscreteTables::build(
                        &self.sampler,
                        light.as_ref(),
                        &shape,
                        self.covered == CoveredSamples::Refined,
                        &self.name,
                    )
                })?)
            }
            CoveredSamples::Exact => None,
        };
        let extent = scene.bounds().union(light.bounds()).diagonal();
        let polygon = shape.plane.as_ref().map(|pl| {
            let c = shape.center.as_dvec3();
            pl.polygon
                .iter()
                .map(|v| (v.as_dvec3() - c).as_vec3())
                .collect()
        });
        let cd = shape.center.as_dvec3();
        let centred_edges = sil
            .iter()
            .map(|&i| CentredEdge::new(&edges[i as usize], cd))
            .collect();
        let wedges = stats.time(DcsPhase::Wedges, || wedges(&edges, &sil, &shape));
        let planar = shape.plane.as_ref().map(|pl| PlanarLight {
            u: pl.u,
            v: pl.v,
            normal: pl.u.cross(pl.v),
        });
        let rect = match (light.geometry(), &shape.plane, light.is_textured()) {
            (LightGeometry::Rectangle { half_u, half_v, .. }, Some(pl), false) => {
                Some(RectMap::new(half_u, half_v, pl.u, pl.v))
            }
            _ => None,
        };
        let (scan, scan_lanes) = wedges
            .par_iter()
            .map(|w| {
                let pe = shape.plane.as_ref().map(|pl| {
                    let (u, v) = (pl.u.as_dvec3(), pl.v.as_dvec3());
                    PlanarEdge::new(&edges[w.edge as usize], cd, u, v)
                });
                ScanWedge::new(w, pe)
            })
            .unzip();
        let offset = RayOffset::for_light(&*light);
        let p = Prepared {
            rays: self.rays.as_ref().map(|_| RayPath::default()),
            planar,
            rect,
            scan,
            scan_lanes,
            polygon,
            centred_edges,
            scene,
            light,
            shape,
            edges,
            silhouettes: sil,
            units,
            sides: one_sided,
            offset,
            extent: extent as f64,
            tables,
        };
        Ok(PreparedDcs {
            config: self.clone(),
            p: Arc::new(p),
            stats,
        })
    }

    /// This configuration prepared for the scene and light `other` was prepared for, sharing
    /// `other`'s edges, silhouettes and wedges when nothing of them depends on what differs:
    /// the same silhouette detection, exact covered samples on both sides (the tables of
    /// section 7.3 depend on the samples) and no shadow-ray side (it is built on its own
    /// configuration's samples). Otherwise it prepares afresh. A chooser that probes with one
    /// sample count and then runs another pays for the preparation once; the counter
    /// `preparation-shared` says which happened.
    ///
    /// # Errors
    /// As [`Dcs::prepare_dcs`], when it prepares afresh.
    pub fn prepare_sharing(&self, other: &PreparedDcs) -> Result<PreparedDcs, TechniqueError> {
        let o = &other.config;
        let shareable = self.detection == o.detection
            && self.covered == CoveredSamples::Exact
            && o.covered == CoveredSamples::Exact
            && self.rays.is_none()
            && o.rays.is_none();
        if !shareable {
            let mut fresh = self.prepare_dcs(other.p.scene.clone(), other.p.light.clone())?;
            fresh.stats.add(DcsCounter::PreparationShared, 0);
            return Ok(fresh);
        }
        self.capabilities()
            .require(&self.name, other.p.scene.as_ref(), other.p.light.as_ref())?;
        let mut stats = Stats::default();
        stats.add(DcsCounter::PreparationShared, 1);
        stats.add(DcsCounter::Edges, other.p.edges.len() as u64);
        stats.add(
            DcsCounter::SilhouetteEdges,
            other.p.silhouettes.len() as u64,
        );
        Ok(PreparedDcs {
            config: self.clone(),
            p: Arc::clone(&other.p),
            stats,
        })
    }

    /// The estimate of `view` on prepared data `p`, with `output` per sample.
    pub(super) fn run(
        &self,
        p: &Prepared,
        view: &ViewSamples,
        output: PerSampleOutput,
    ) -> Result<Estimate, TechniqueError> {
        let mut stats = Stats::default();
        // Rays give no depth complexities: a frame whose counters are read is DCS's alone.
        let (f, plan) = self.frame(p, view, output != PerSampleOutput::Counters, &mut stats)?;
        self.finish(p, &f, &plan, view, output, stats)
    }

    /// Whether `other`'s frame (integration constants, counter width, square plan) is this
    /// configuration's too: it depends on the preparation, the covered-sample test, a forced
    /// counter width and the shadow-ray side, never on the samples.
    pub(super) fn same_frame(&self, other: &Dcs) -> bool {
        self.covered == other.covered
            && self.forced_bits == other.forced_bits
            && self.rays.is_none()
            && other.rays.is_none()
    }

    /// The per-pixel pass of [`Dcs::run`] (Algorithm 2's steps 3 and 4) on a frame already
    /// built, by this configuration or one with [`Dcs::same_frame`], and its estimate.
    pub(super) fn finish(
        &self,
        p: &Prepared,
        f: &Frame<'_>,
        plan: &Plan<'_>,
        view: &ViewSamples,
        output: PerSampleOutput,
        mut stats: Stats,
    ) -> Result<Estimate, TechniqueError> {
        let n = self.sampler.count() as usize;
        let out = PixelOutput {
            n,
            words: n.div_ceil(64),
            textured: p.light.is_textured(),
            output,
        };
        let w = view.width() as usize;
        let strips = stats.time(DcsPhase::DepthComplexity, || {
            self.squares(plan, |job, buffers| {
                let rect = job.rect;
                let rw = rect.width() as usize;
                let mut r = out.square(rect.len());
                let values = out.textured || output == PerSampleOutput::Counters || p.units != 1;
                let mut counts = Counts::default();
                self.run_square(
                    p,
                    f,
                    plan,
                    job,
                    values,
                    &mut counts,
                    buffers,
                    |i, _, class, scratch| {
                        let x =
                            (i / w - rect.rows.0 as usize) * rw + (i % w - rect.cols.0 as usize);
                        out.write(&mut r, x, class, scratch);
                    },
                );
                r.counts = counts;
                r
            })
        });
        let (vis, counts) = out.image(view, &strips)?;
        record_counts(&mut stats, &counts, plan.block_wedges, plan.predicted);
        vis.validate()?;
        Ok(Estimate::new(vis, stats))
    }
}

impl PreparedDcs {
    /// The visibility and per-sample bits of `view` under this configuration and each of
    /// `others`, as their own [`PreparedShadows::estimate`] would give them, with one frame
    /// (integration constants, counter width, square plan) for all where they share it: the
    /// same preparation ([`Dcs::prepare_sharing`]) and configurations that differ only in their
    /// samples. Independent replicates of one estimate (a variance probe) cost one frame and
    /// several per-pixel passes. An estimate that cannot share the frame is made on its own.
    ///
    /// # Errors
    /// As [`PreparedShadows::estimate`].
    pub fn estimate_replicates(
        &self,
        others: &[&PreparedDcs],
        view: &ViewSamples,
    ) -> Result<Vec<Estimate>, TechniqueError> {
        let output = PerSampleOutput::Bits;
        let mut stats = Stats::default();
        let (f, plan) = self.config.frame(&self.p, view, true, &mut stats)?;
        let mut out = vec![
            self.config
                .finish(&self.p, &f, &plan, view, output, stats)?,
        ];
        for o in others {
            let mut est = if Arc::ptr_eq(&self.p, &o.p) && self.config.same_frame(&o.config) {
                let mut stats = Stats::default();
                stats.add(DcsCounter::FrameShared, 1);
                o.config.finish(&o.p, &f, &plan, view, output, stats)?
            } else {
                o.config.run(&o.p, view, output)?
            };
            est.darken_behind_light(view, o.p.light.as_ref());
            out.push(est);
        }
        out[0].darken_behind_light(view, self.p.light.as_ref());
        Ok(out)
    }
}
