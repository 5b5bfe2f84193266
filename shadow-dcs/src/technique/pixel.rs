//! The per-pixel pass of DCS (section 4.2, Algorithm 1 for one view sample): its horizon class,
//! the set-up of its light samples, the covered samples of each wedge pair (the light-plane
//! test, the 3D test or the section 7.3 tables) and the counter updates, outer wedges first
//! (sections 4.3 and 4.4).

use super::*;
use shadow_core::geometry::ray_hits_triangle;

/// Where a sample's segment ends, as a fraction of the way to the sample (the reference's).
const SEGMENT_END: f64 = 1.0 - 1e-6;

/// One view sample's pass (Algorithm 1 for one pixel): what each of its steps reads (the
/// technique, its preparation, the frame, the pixel) and writes (the scratch, the counts).
pub(super) struct PixelPass<'a, 'v> {
    /// The configuration.
    pub(super) dcs: &'a Dcs,
    /// The scene and light as prepared.
    pub(super) p: &'a Prepared,
    /// The frame (view samples, constants, horizons).
    pub(super) f: &'a Frame<'v>,
    /// The pixel's index in the view.
    pub(super) i: usize,
    /// The pixel's view sample.
    pub(super) s: &'a ViewSample,
    /// Per-thread buffers the pass fills.
    pub(super) scratch: &'a mut Scratch,
    /// Work counts.
    pub(super) counts: &'a mut Counts,
}

impl PixelPass<'_, '_> {
    /// Per-sample visibility of pixel `i` into `scratch.visible` (with `scratch.want_values`,
    /// also `scratch.vis` and depth complexities into `scratch.depth`), and its samples'
    /// radiances into `scratch.radiances` when the light is textured (they weigh eq. 2; none for
    /// a pixel whose integration constant alone puts it in the umbra; the whole light samples
    /// into `scratch.samples` only where the samples were set up), from its
    /// wedge pairs `entries` (and, for the light-plane test, their `tests`). Returns the class.
    pub(super) fn run(&mut self, entries: &[Pair], tests: &[PlanarTest]) -> PixelClass {
        let Self {
            dcs, p, f, i, s, ..
        } = *self;
        // The refined tables of section 7.3 settle what they can of the index's candidates.
        let pc = f.origins[i].as_dvec3() - p.shape.center.as_dvec3();
        let refined = match (dcs.covered, &p.tables) {
            (CoveredSamples::Refined, Some(t)) => Some(Refined {
                tables: t,
                edges: &p.centred_edges,
                p: pc,
                pixel: s.pixel,
            }),
            _ => None,
        };
        let pairs = entries.len() + tests.len();
        let indexed = p.shape.plane.is_some()
            && (dcs.covered == CoveredSamples::Exact || refined.is_some())
            && pairs >= INDEX_MIN_PAIRS;
        let Some(mut start) = self.start(indexed) else {
            return PixelClass::Skipped;
        };
        if let (Some(poly), false) = (&p.polygon, pairs == 0) {
            self.scratch.polygon.set(poly, f.centred[i]);
        }
        // Each pair's covered-sample test. The light-overlap test decides whether the pixel
        // needs per-sample work at all: its samples are set up at the first pair that may cover
        // the light (at once when the horizon cuts the light). With the angular index the later
        // pairs go straight to their candidates, which drop off-light pairs more cheaply.
        // The scan gives the light-plane tests to exactly the pixels marked for them.
        debug_assert!(start.planar || tests.is_empty());
        debug_assert!(!start.planar || entries.is_empty());
        if !tests.is_empty() {
            self.ensure_ready(&mut start);
            Dcs::planar_pairs(tests, indexed, self.scratch, self.counts);
        }
        for pair in entries {
            let Some(test) = p.centred_edges[pair.edge as usize].test(pc) else {
                self.counts.ties += 1;
                continue;
            };
            if (!start.ready || !indexed)
                && p.polygon.is_some()
                && !test.may_cover(&self.scratch.polygon)
            {
                self.counts.off_light += 1;
                continue;
            }
            self.ensure_ready(&mut start);
            if indexed {
                // Candidates a batch at a time (their sector arithmetic vectorises).
                let scratch = &mut *self.scratch;
                scratch.batch.push(test);
                scratch.batch_k.push(pair.k as i64);
                if refined.is_some() {
                    scratch.batch_edge.push(pair.edge);
                }
                if scratch.batch.len() == BATCH {
                    Dcs::indexed_updates(scratch, self.counts, refined.as_ref());
                }
            } else {
                self.covered_update(pc + p.shape.center.as_dvec3(), pair, &test);
            }
        }
        if !self.scratch.batch.is_empty() {
            Dcs::indexed_updates(self.scratch, self.counts, refined.as_ref());
        }
        if !p.sides.explicit_list.is_empty() {
            self.explicit_updates(&mut start);
        }
        self.finish(&start)
    }

    /// The crossings of the pixel's sample segments with the triangles the light may pass
    /// through ([`crate::stages::edges::Sides`]), tested one by one and added as updates: the
    /// part of the depth complexity no wedge carries.
    fn explicit_updates(&mut self, start: &mut PixelStart) {
        let Self {
            dcs, p, f, i, s, ..
        } = *self;
        let n = dcs.sampler.count() as usize;
        let words = n.div_ceil(64);
        let o = f.origins[i].as_dvec3();
        let scratch = &mut *self.scratch;
        dcs.sampler
            .unit_samples(s.pixel, &mut scratch.explicit_units);
        scratch.explicit_samples.clear();
        p.light
            .sample_into(&scratch.explicit_units, &mut scratch.explicit_samples);
        let list = &p.sides.explicit_list;
        scratch.explicit_masks.clear();
        scratch.explicit_masks.resize(list.len() * words, 0);
        let mut any = false;
        for (&t, mask) in list.iter().zip(scratch.explicit_masks.chunks_mut(words)) {
            let [a, b, c] = p.scene.triangle(t as usize).map(|v| v.as_dvec3());
            for (k, y) in scratch.explicit_samples.iter().enumerate() {
                // The reference's segment: it stops short of the light sample by a relative
                // `1e-6`, so a face the sample lies on does not hide it.
                if ray_hits_triangle(o, y.position.as_dvec3() - o, a, b, c, SEGMENT_END) {
                    mask[k / 64] |= 1 << (k % 64);
                    any = true;
                }
            }
        }
        if !any {
            return;
        }
        self.ensure_ready(start);
        let scratch = &mut *self.scratch;
        let semi = p.scene.has_semi_opaque();
        for (&t, mask) in list.iter().zip(scratch.explicit_masks.chunks(words)) {
            if mask.iter().all(|&m| m == 0) {
                continue;
            }
            let k = if semi {
                (p.scene.opacities()[t as usize].clamp(0.0, 1.0) * p.units as f32).ceil() as i64
            } else {
                1
            };
            scratch
                .updates
                .push(mask, k, &mut self.counts.covered_updates);
        }
    }

    /// The start of pixel `i`'s pass: its scratch emptied, its class when it faces away from the
    /// whole light (`None`, its values set), else its integration constant and whether it takes
    /// the light-plane test, with its samples set up at once when the horizon cuts the light
    /// (`indexed`: with the angular index).
    fn start(&mut self, indexed: bool) -> Option<PixelStart> {
        let Self { dcs, f, i, .. } = *self;
        let (scratch, counts) = (&mut *self.scratch, &mut *self.counts);
        let n = dcs.sampler.count() as usize;
        let horizon = f.horizon[i];
        if !scratch.begin_pixel(n, horizon == Horizon::Below, counts) {
            return None;
        }
        let mut d0 = f.constants[i];
        if d0 < 0 {
            counts.negative += 1;
            d0 = 0;
        }
        let mut start = PixelStart {
            d0: d0 as u64,
            indexed,
            // The light-plane form of the test (planar lights, exact covered samples, a
            // receiver clear of the light's plane).
            planar: f.planar_ok.get(i).copied().unwrap_or(false),
            ready: false,
        };
        if horizon == Horizon::Mixed {
            self.ensure_ready(&mut start);
        }
        Some(start)
    }

    /// Sets the pixel's samples up unless they are.
    fn ensure_ready(&mut self, start: &mut PixelStart) {
        if !start.ready {
            let all_above = self.f.horizon[self.i] == Horizon::Above;
            self.sample_setup(start.indexed, all_above, start.planar);
            start.ready = true;
        }
    }

    /// The end of a pixel's pass: its integration constant for every sample when it set no
    /// sample up, else its counters from the updates in `scratch`; returns its class.
    fn finish(&mut self, start: &PixelStart) -> PixelClass {
        let Self { dcs, p, f, s, .. } = *self;
        let (scratch, counts) = (&mut *self.scratch, &mut *self.counts);
        let n = dcs.sampler.count() as usize;
        let words = n.div_ceil(64);
        let d0 = start.d0;
        let units = p.units as f32;
        let textured = p.light.is_textured();
        let values = scratch.want_values;
        if !start.ready {
            // No wedge: every sample has the integration constant.
            counts.constant_only += 1;
            let v = 1.0 - (d0 as f32 / units).min(1.0);
            if d0 == 0 {
                fill_first(&mut scratch.visible, n);
            }
            if values {
                scratch.vis.resize(n, v);
                scratch.depth.resize(n, d0);
            }
            // In the umbra every sample's weight is zero: eq. 2 needs no radiance. Elsewhere
            // only the radiances, not the positions.
            if textured && v > 0.0 {
                dcs.sampler.unit_samples(s.pixel, &mut scratch.units);
                let light = p.light.as_ref();
                light.radiances_into(&scratch.units, &mut scratch.radiances);
            }
            return if d0 == 0 {
                PixelClass::Lit
            } else if v == 0.0 {
                PixelClass::Umbra
            } else {
                PixelClass::Penumbra
            };
        }
        counts.per_sample += 1;
        // Packed counters, outer wedges (k > 0) before inner ones (section 4.4); wider ones on
        // overflow, plain signed counters as the last resort. Bit-sliced when only the zero
        // counters are read, the paper's lanes when every depth complexity is.
        let mut done = false;
        for bits in WIDTHS.into_iter().filter(|&b| b >= f.bits) {
            let (masks, weights) = (&scratch.updates.masks, &scratch.updates.weights);
            let fits = if values {
                counters::run(&mut scratch.packed, bits, n, d0, masks, weights)
            } else {
                counters::run(&mut scratch.sliced, bits, n, d0, masks, weights)
            };
            if fits.is_ok() {
                if !values {
                    // Only which samples are visible: the zero counters above the horizon.
                    scratch.sliced.zero_mask_into(&mut scratch.visible);
                    let mut any = 0u64;
                    let mut all = true;
                    for (k, (v, a)) in scratch.visible.iter_mut().zip(&scratch.above).enumerate() {
                        *v &= *a;
                        any |= *v;
                        let left = n - k * 64;
                        all &= *v
                            == if left >= 64 {
                                u64::MAX
                            } else {
                                (1 << left) - 1
                            };
                    }
                    return if all {
                        PixelClass::Lit
                    } else if any == 0 {
                        PixelClass::Umbra
                    } else {
                        PixelClass::Penumbra
                    };
                }
                scratch.packed.unpack_into(&mut scratch.depth);
                done = true;
                break;
            }
            counts.escalations += 1;
        }
        if !done {
            counts.plain_fallback += 1;
            scratch.plain.clear();
            scratch.plain.resize(n, d0 as i64);
            let u = &scratch.updates;
            for (m, &k) in u.masks.chunks(words).zip(&u.weights) {
                for j in 0..n {
                    if m[j / 64] >> (j % 64) & 1 == 1 {
                        scratch.plain[j] = scratch.plain[j].saturating_add(k);
                    }
                }
            }
            if scratch.plain.iter().any(|&d| d < 0) {
                counts.negative += 1;
            }
            scratch
                .depth
                .extend(scratch.plain.iter().map(|&d| d.max(0) as u64));
        }
        let mut tally = ClassTally::new();
        // One unit per occluder (no semi-opaque scene): the visibility is whether the depth
        // complexity is 0, as the general expression gives it.
        let whole = units == 1.0;
        for k in 0..n {
            let v = if scratch.above[k / 64] >> (k % 64) & 1 == 1 {
                let d = scratch.depth[k];
                if whole {
                    if d == 0 { 1.0 } else { 0.0 }
                } else {
                    1.0 - (d as f32 / units).min(1.0)
                }
            } else {
                scratch.depth[k] = u64::MAX;
                0.0
            };
            tally.add(k, v, &mut scratch.visible);
            scratch.vis.push(v);
        }
        tally.class()
    }

    /// A per-sample pixel's samples: positions, the horizon mask, the samples relative to the
    /// view sample (in the light plane with `planar`), the angular index (`indexed`), and empty
    /// update lists. What depends on the samples alone comes from the pixel's shared set when
    /// it has one (correlated and interleaved sampling, [`crate::accel::shared_sets`]), built once.
    fn sample_setup(&mut self, indexed: bool, all_above: bool, planar: bool) {
        let Self {
            dcs, p, f, i, s, ..
        } = *self;
        let (scratch, counts) = (&mut *self.scratch, &mut *self.counts);
        let origin = f.origins[i];
        let n = dcs.sampler.count() as usize;
        let words = n.div_ceil(64);
        dcs.sampler.unit_samples(s.pixel, &mut scratch.units);
        let light = p.light.as_ref();
        scratch.samples.clear();
        scratch.radiances.clear();
        // A constant rectangle light wholly above the receiver needs no world positions: the
        // light-plane coordinates are an affine map of the unit samples (positions are still
        // made under debug assertions, to check the horizon).
        let rect = p.rect.as_ref().filter(|_| planar && all_above);
        let form = match (&p.planar, planar, rect) {
            (Some(_), true, Some(_)) => SetForm::PlanarRect,
            (Some(_), true, None) => SetForm::Planar,
            _ => SetForm::Spatial,
        };
        // The radiances of a textured light weigh the visibilities (eq. 2): its pixels set
        // their samples up themselves.
        let textured = light.is_textured();
        let shared = (dcs.share_sets && !textured)
            .then(|| dcs.sampler.shared_set(s.pixel))
            .flatten();
        let units = &scratch.units;
        match shared {
            Some(k) => {
                // Built with its index, which the pixels of the set that take one then share.
                let built = scratch.shared.lend(k, form, &mut scratch.set, |set| {
                    Dcs::set_up_samples(p, form, units, true, set);
                });
                counts.shared_sets_built += u64::from(built);
                counts.shared_set_pixels += 1;
            }
            None => {
                scratch.shared.restore(&mut scratch.set);
                scratch.set.positions.clear();
                if textured {
                    light.sample_into(units, &mut scratch.samples);
                    scratch
                        .set
                        .positions
                        .extend(scratch.samples.iter().map(|l| l.position));
                    scratch
                        .radiances
                        .extend(scratch.samples.iter().map(|l| l.radiance));
                }
                Dcs::set_up_samples(p, form, units, indexed, &mut scratch.set);
            }
        }
        // Samples above the horizon (the reference's rule), every one when the whole light is
        // surely above.
        if all_above {
            scratch.above.clear();
            scratch.above.resize(words, u64::MAX);
            if !n.is_multiple_of(64) {
                scratch.above[words - 1] = (1 << (n % 64)) - 1;
            }
            if cfg!(debug_assertions) {
                let mut check = Vec::new();
                horizon_mask_into(&scratch.set.positions, s, origin, &mut check);
                assert_eq!(
                    scratch.above, check,
                    "a light surely above the horizon has a sample below it"
                );
            }
        } else {
            horizon_mask_into(&scratch.set.positions, s, origin, &mut scratch.above);
        }
        scratch.updates.clear();
        if form == SetForm::Spatial {
            scratch.relative.set(origin, &scratch.set.positions);
        }
        scratch.mask.clear();
        scratch.mask.resize(words, 0);
    }

    /// The samples one pair's edge covers (section 7.3 tables, or the exact test on every
    /// sample above the horizon), appended to the pixel's updates when there is any.
    fn covered_update(&mut self, o: DVec3, pair: &Pair, test: &EdgeTest) {
        let Self { dcs, p, s, .. } = *self;
        let (scratch, counts) = (&mut *self.scratch, &mut *self.counts);
        counts.edge_tests += 1;
        let mask = &mut scratch.mask;
        let any = match (&dcs.covered, &p.tables) {
            (CoveredSamples::Discrete | CoveredSamples::Refined, Some(t)) => t.mask(
                s.pixel,
                test,
                o,
                &p.edges[p.silhouettes[pair.edge as usize] as usize],
                &scratch.relative,
                &scratch.above,
                mask,
            ),
            _ => test.mask(&scratch.relative, &scratch.above, mask),
        };
        if any {
            scratch
                .updates
                .push(mask, pair.k as i64, &mut counts.covered_updates);
        }
    }
}

impl Dcs {
    /// The horizon class of a receiver: the reference's rule, a sample counts when it lies
    /// above the tangent plane both from the surface point and from the offset origin.
    pub(super) fn horizon(shape: &LightShape, s: &ViewSample, origin: Vec3) -> Horizon {
        let n = s.geometric_normal.as_dvec3();
        let [(lo1, hi1), (lo2, hi2)] =
            shape.ranges(n, -n.dot(s.position.as_dvec3()), -n.dot(origin.as_dvec3()));
        let reach = shape.center.as_dvec3().length() + f64::from(shape.radius);
        let bound = HORIZON_BOUND
            * n.length()
            * (reach
                + s.position
                    .as_dvec3()
                    .length()
                    .max(origin.as_dvec3().length()));
        if lo1 > bound && lo2 > bound {
            Horizon::Above
        } else if lo1 > 0.0 && lo2 > 0.0 {
            Horizon::Grazing
        } else if !(hi1 > 0.0 && hi2 > 0.0) {
            Horizon::Below
        } else {
            Horizon::Mixed
        }
    }

    /// What a pixel's samples need of their unit samples `units` alone, in `form`, into `set`:
    /// the world positions (unless already there, as a textured light's samples put them;
    /// none for the rectangle form outside debug builds), the light-plane coordinates (the
    /// light-plane forms) and, with `indexed`, the angular index.
    pub(super) fn set_up_samples(
        p: &Prepared,
        form: SetForm,
        units: &[Vec2],
        indexed: bool,
        set: &mut SampleSet,
    ) {
        let n = units.len();
        let light = p.light.as_ref();
        let positions_needed = form != SetForm::PlanarRect || cfg!(debug_assertions);
        if set.positions.is_empty() && positions_needed {
            light.positions_into(units, &mut set.positions);
        }
        match (form, &p.planar, p.rect.as_ref()) {
            (SetForm::PlanarRect, Some(_), Some(r)) => set.planar.set_rect(units, r),
            (SetForm::Planar | SetForm::PlanarRect, Some(pl), _) => {
                set.planar.set(&set.positions, p.shape.center, pl.u, pl.v);
            }
            _ => {
                if let (Some(plane), true) = (&p.shape.plane, indexed) {
                    set.angular.build(plane, p.shape.center, &set.positions);
                }
                return;
            }
        }
        if indexed {
            set.angular.build_planar(&set.planar, n);
        }
    }

    /// The covered samples of the batched tests (`scratch.batch`, emptied): their angular
    /// candidates, then the exact test on those (with `refined`, on those the line table leaves
    /// undecided), appended to the pixel's updates when any.
    pub(super) fn indexed_updates(
        scratch: &mut Scratch,
        counts: &mut Counts,
        refined: Option<&Refined>,
    ) {
        let words = scratch.above.len();
        let n = scratch.batch.len();
        scratch.batch_candidates.resize(BATCH * words, 0);
        scratch.batch_inner.resize(BATCH * words, 0);
        let any = scratch.set.angular.candidates_batch(
            &scratch.batch,
            &scratch.above,
            &mut scratch.batch_candidates,
            refined.map(|_| &mut scratch.batch_inner[..]),
        );
        counts.edge_tests += n as u64;
        for (i, (test, k)) in scratch.batch.iter().zip(&scratch.batch_k).enumerate() {
            if any >> i & 1 == 0 {
                counts.sector_empty += 1;
                continue;
            }
            let cand = &scratch.batch_candidates[i * words..(i + 1) * words];
            let mask = &mut scratch.mask;
            let few = cand.iter().map(|w| w.count_ones()).sum::<u32>() <= FEW_CANDIDATES;
            // With the refined tables, a pair with many candidates asks the line table first:
            // candidates in the sector's inner buckets and surely beyond the line are covered,
            // the exact test takes those the line leaves undecided.
            let decided = match (refined, few) {
                (Some(r), false) => {
                    let (a, b) = r.edges[scratch.batch_edge[i] as usize].ends();
                    match r.tables.refined_line(r.pixel, r.p, a, b) {
                        LineMasks::Unknown => None,
                        LineMasks::NoneBeyond => Some(false),
                        LineMasks::Cell { beyond, maybe } => {
                            counts.line_cells += 1;
                            let inner = &scratch.batch_inner[i * words..(i + 1) * words];
                            let undecided = &mut scratch.undecided;
                            undecided.clear();
                            let mut open = 0;
                            for j in 0..words {
                                mask[j] = inner[j] & beyond[j];
                                undecided.push(cand[j] & maybe[j] & !mask[j]);
                                open |= undecided[j];
                            }
                            if open != 0 {
                                test.add_covered(&scratch.relative, undecided, mask);
                            }
                            Some(mask.iter().any(|w| *w != 0))
                        }
                    }
                }
                _ => None,
            };
            let covered = match decided {
                Some(covered) => covered,
                None if few => {
                    mask.fill(0);
                    test.add_covered(&scratch.relative, cand, mask);
                    mask.iter().any(|w| *w != 0)
                }
                None => test.mask(&scratch.relative, cand, mask),
            };
            if covered {
                scratch.updates.push(mask, *k, &mut counts.covered_updates);
            }
        }
        scratch.batch.clear();
        scratch.batch_k.clear();
        scratch.batch_edge.clear();
    }

    /// The covered samples of every pair of a pixel by its light-plane test (`tests`, set up
    /// by the wedge scan; samples set up), four pairs at a time: their sectors' bucket ranges
    /// (with `indexed`; otherwise every sample is a candidate), then the exact test on the
    /// candidates, appended to the pixel's updates when any.
    #[inline(never)]
    pub(super) fn planar_pairs(
        tests: &[PlanarTest],
        indexed: bool,
        scratch: &mut Scratch,
        counts: &mut Counts,
    ) {
        let words = scratch.above.len();
        scratch.mask.resize(words, 0);
        scratch.batch_candidates.resize(words, 0);
        counts.edge_tests += tests.len() as u64;
        if indexed {
            // Up to four words of samples (`dcs-256`): candidates, samples and covered samples
            // as fixed arrays.
            let done = match words {
                1 => Self::indexed_pairs::<1>(tests, scratch, counts),
                2 => Self::indexed_pairs::<2>(tests, scratch, counts),
                3 => Self::indexed_pairs::<3>(tests, scratch, counts),
                4 => Self::indexed_pairs::<4>(tests, scratch, counts),
                _ => false,
            };
            if done {
                return;
            }
        }
        for quad in tests.chunks(4) {
            let ranges = indexed.then(|| {
                let mut four = [PlanarTest::NONE; 4];
                four[..quad.len()].copy_from_slice(quad);
                QuadRanges::of_tests(&four)
            });
            for (j, test) in quad.iter().enumerate() {
                let mut hit = 0u64;
                if let Some(r) = &ranges {
                    let cand = &mut scratch.batch_candidates;
                    if !scratch
                        .set
                        .angular
                        .quad_candidates(r, j, &scratch.above, cand)
                    {
                        counts.sector_empty += 1;
                        continue;
                    }
                    for (w, &c) in cand.iter().enumerate() {
                        let m = test.covered_in(&scratch.set.planar, w, c);
                        scratch.mask[w] = m;
                        hit |= m;
                    }
                } else {
                    for (w, &a) in scratch.above.iter().enumerate() {
                        let m = test.covered_word(&scratch.set.planar, w) & a;
                        scratch.mask[w] = m;
                        hit |= m;
                    }
                }
                if hit != 0 {
                    scratch.updates.push(
                        &scratch.mask,
                        i64::from(test.k),
                        &mut counts.covered_updates,
                    );
                }
            }
        }
    }

    /// [`Dcs::planar_pairs`] with the angular index on `W` words of samples (`scratch.above`
    /// has `W` words; `false`, nothing done, when it has not): four pairs' sectors at a time,
    /// each pair's candidates word by word, then the exact test on them. The word count is a
    /// constant so that the candidate words live in fixed arrays rather than slices of any
    /// length (the measured gain is in `docs/history/`).
    #[inline(always)]
    pub(super) fn indexed_pairs<const W: usize>(
        tests: &[PlanarTest],
        scratch: &mut Scratch,
        counts: &mut Counts,
    ) -> bool {
        let Ok(above) = <[u64; W]>::try_from(&scratch.above[..]) else {
            return false;
        };
        let samples = &scratch.set.planar;
        let (xs, ys) = (samples.words_x::<W>(), samples.words_y::<W>());
        let Some(rows) = scratch.set.angular.rows::<W>() else {
            return false;
        };
        let updates = &mut scratch.updates;
        let (mut empty, mut covered) = (0, 0);
        let mut quad_of = |four: &[PlanarTest; 4], n: usize| {
            let r = QuadRanges::of_tests(four);
            for (j, test) in four[..n].iter().enumerate() {
                let mut cand = r.words(rows, j);
                let mut any = 0;
                for (c, a) in cand.iter_mut().zip(&above) {
                    *c &= a;
                    any |= *c;
                }
                if any == 0 {
                    empty += 1;
                    continue;
                }
                let hit: [u64; W] =
                    std::array::from_fn(|w| test.covered_of(&xs[w], &ys[w], cand[w]));
                if hit.iter().any(|h| *h != 0) {
                    updates.push(&hit, i64::from(test.k), &mut covered);
                }
            }
        };
        let (whole, rest) = tests.as_chunks::<4>();
        for four in whole {
            quad_of(four, 4);
        }
        if !rest.is_empty() {
            let mut four = [PlanarTest::NONE; 4];
            four[..rest.len()].copy_from_slice(rest);
            quad_of(&four, rest.len());
        }
        counts.sector_empty += empty;
        counts.covered_updates += covered;
        true
    }
}
