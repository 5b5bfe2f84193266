//! Typed statistics: the phases, counters and gauges an estimate reports (DESIGN section 3,
//! `stats.json`).
//!
//! Each crate declares what it records as enums with [`crate::statistics!`], one per kind
//! ([`Counter`], [`Gauge`], [`PhaseName`]), each variant carrying the name it has in
//! `stats.json`. [`Stats`] takes only those types, so a test names a counter by its type and a
//! renamed or misspelt one fails to compile; the names stay strings in the file, so reports and
//! tools read them as before. The statistics every technique shares (the light-side rule, the
//! lights' skips, direct light) are [`CoreCounter`] and [`CorePhase`].

use std::collections::BTreeMap;
use std::time::Instant;

use serde::Serialize;

/// A counter: an amount of work done or skipped (rays, pixels, pairs). Amounts add up when
/// stats merge.
pub trait Counter: Copy {
    /// Its name in `stats.json`.
    fn name(self) -> &'static str;
}

/// A gauge: a level (a largest value, a width chosen, a map's side). Merging keeps the larger.
pub trait Gauge: Copy {
    /// Its name in `stats.json`.
    fn name(self) -> &'static str;
}

/// A phase: a named step whose wall-clock (and, on a GPU, device) time is recorded.
pub trait PhaseName: Copy {
    /// Its name in `stats.json`.
    fn name(self) -> &'static str;
}

/// Declares an enum of statistics of one kind ([`Counter`], [`Gauge`] or [`PhaseName`]), each
/// variant with its name in `stats.json`, and `ALL`, every variant in order.
///
/// ```
/// shadow_core::statistics! {
///     Counter:
///     /// What the example counts.
///     pub enum ExampleCounter {
///         /// Rays traced.
///         Rays => "rays",
///     }
/// }
/// let mut stats = shadow_core::Stats::default();
/// stats.add(ExampleCounter::Rays, 3);
/// assert_eq!(stats.counter(ExampleCounter::Rays), Some(3));
/// assert_eq!(stats.counters["rays"], 3);
/// ```
#[macro_export]
macro_rules! statistics {
    ($kind:ident: $(#[$m:meta])* $vis:vis enum $E:ident {
        $( $(#[$vm:meta])* $V:ident => $s:literal ),* $(,)?
    }) => {
        $(#[$m])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        $vis enum $E { $( $(#[$vm])* $V ),* }
        impl $E {
            /// Every statistic of this kind, in declaration order.
            #[allow(dead_code)]
            pub const ALL: &'static [$E] = &[$($E::$V),*];
        }
        impl $crate::stats::$kind for $E {
            fn name(self) -> &'static str {
                match self { $($E::$V => $s),* }
            }
        }
    };
}

statistics! {
    Counter:
    /// Counters every technique's estimate shares, recorded by the shared steps in core.
    pub enum CoreCounter {
        /// Pixels behind the plane a planar light emits from, darkened by the light-side rule.
        PixelsBehindLight => "pixels-behind-light",
        /// Lights that reach no receiver, skipped ([`crate::lights::PreparedLights`]).
        LightsSkipped => "lights-skipped",
        /// Lights estimated with shadows.
        LightsShadowed => "lights-shadowed",
        /// Lights the technique refused, estimated by the fallback.
        LightsFallback => "lights-fallback",
    }
}

statistics! {
    PhaseName:
    /// Phases every technique's estimate shares.
    pub enum CorePhase {
        /// Direct light from the technique's per-sample visibility.
        Direct => "direct",
    }
}

/// Time of one phase.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Phase {
    /// Phase name.
    pub name: String,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// Seconds the GPU spent on the phase's work (timestamp queries), when it ran on a device
    /// that measures them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub device_seconds: Option<f64>,
}

/// Per-phase times, counters of work done and skipped, and gauges.
///
/// Counters are amounts (rays, pixels, pairs): they add up when stats merge, saturate at
/// `u64::MAX` and record the saturation in `saturated`, so they never wrap silently. Gauges are
/// levels (a largest value, a width chosen, a map's side): merging keeps the larger. Looking a
/// statistic up gives `None` when it was never recorded.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Stats {
    /// Phases in the order they ran.
    pub phases: Vec<Phase>,
    /// Counters by name.
    pub counters: BTreeMap<String, u64>,
    /// Gauges by name.
    pub gauges: BTreeMap<String, u64>,
    /// Counters split by a bucket (a count of samples, a level), by name then bucket.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub histograms: BTreeMap<String, BTreeMap<u64, u64>>,
    /// Counters that saturated.
    pub saturated: Vec<String>,
}

impl Stats {
    /// Runs `f`, adding its wall-clock time to `phase`.
    pub fn time<T>(&mut self, phase: impl PhaseName, f: impl FnOnce() -> T) -> T {
        let t0 = Instant::now();
        let r = f();
        self.add_time(phase, t0.elapsed().as_secs_f64());
        r
    }

    /// Adds `seconds` of wall-clock time to `phase`.
    pub fn add_time(&mut self, phase: impl PhaseName, seconds: f64) {
        self.phase_entry(phase.name()).seconds += seconds;
    }

    /// Adds `seconds` of GPU time to `phase`.
    pub fn add_device_time(&mut self, phase: impl PhaseName, seconds: f64) {
        let p = self.phase_entry(phase.name());
        *p.device_seconds.get_or_insert(0.0) += seconds;
    }

    fn phase_entry(&mut self, name: &str) -> &mut Phase {
        let at = match self.phases.iter().position(|p| p.name == name) {
            Some(at) => at,
            None => {
                self.phases.push(Phase {
                    name: name.to_string(),
                    seconds: 0.0,
                    device_seconds: None,
                });
                self.phases.len() - 1
            }
        };
        &mut self.phases[at]
    }

    /// Adds `n` to `counter`, saturating (and recording it) on overflow.
    pub fn add(&mut self, counter: impl Counter, n: u64) {
        self.add_named(counter.name(), n);
    }

    fn add_named(&mut self, name: &str, n: u64) {
        let c = self.counters.entry(name.to_string()).or_insert(0);
        match c.checked_add(n) {
            Some(v) => *c = v,
            None => {
                *c = u64::MAX;
                if !self.saturated.iter().any(|s| s == name) {
                    self.saturated.push(name.to_string());
                }
            }
        }
    }

    /// Adds `n` to `bucket` of the histogram `counter`, saturating.
    pub fn add_to_bucket(&mut self, counter: impl Counter, bucket: u64, n: u64) {
        self.add_to_bucket_named(counter.name(), bucket, n);
    }

    fn add_to_bucket_named(&mut self, name: &str, bucket: u64, n: u64) {
        let h = self.histograms.entry(name.to_string()).or_default();
        let c = h.entry(bucket).or_insert(0);
        *c = c.saturating_add(n);
    }

    /// The histogram `counter`, by bucket, or `None` when it was never recorded.
    pub fn histogram(&self, counter: impl Counter) -> Option<&BTreeMap<u64, u64>> {
        self.histograms.get(counter.name())
    }

    /// Raises `gauge` to `v` (a gauge keeps the largest value recorded).
    pub fn gauge_max(&mut self, gauge: impl Gauge, v: u64) {
        self.gauge_max_named(gauge.name(), v);
    }

    fn gauge_max_named(&mut self, name: &str, v: u64) {
        let g = self.gauges.entry(name.to_string()).or_insert(v);
        *g = (*g).max(v);
    }

    /// Total wall-clock time over all phases.
    pub fn total_seconds(&self) -> f64 {
        self.phases.iter().map(|p| p.seconds).sum()
    }

    /// Total GPU time over the phases that measured it, `None` when none did.
    pub fn total_device_seconds(&self) -> Option<f64> {
        self.phases
            .iter()
            .filter_map(|p| p.device_seconds)
            .reduce(|a, b| a + b)
    }

    /// Wall-clock seconds of `phase`, when it ran.
    pub fn phase_seconds(&self, phase: impl PhaseName) -> Option<f64> {
        self.phase(phase).map(|p| p.seconds)
    }

    /// GPU seconds of `phase`, when it ran on a device that measures them.
    pub fn device_seconds(&self, phase: impl PhaseName) -> Option<f64> {
        self.phase(phase).and_then(|p| p.device_seconds)
    }

    fn phase(&self, phase: impl PhaseName) -> Option<&Phase> {
        let name = phase.name();
        self.phases.iter().find(|p| p.name == name)
    }

    /// Merges another set of stats: times and counters add up, gauges keep the larger.
    pub fn merge(&mut self, other: &Stats) {
        for p in &other.phases {
            let mine = self.phase_entry(&p.name);
            mine.seconds += p.seconds;
            if let Some(d) = p.device_seconds {
                *mine.device_seconds.get_or_insert(0.0) += d;
            }
        }
        for (k, v) in &other.counters {
            self.add_named(k, *v);
        }
        for (k, v) in &other.gauges {
            self.gauge_max_named(k, *v);
        }
        for (k, h) in &other.histograms {
            for (bucket, n) in h {
                self.add_to_bucket_named(k, *bucket, *n);
            }
        }
        for s in &other.saturated {
            if !self.saturated.contains(s) {
                self.saturated.push(s.clone());
            }
        }
    }

    /// `counter`, or `None` when it was never recorded.
    pub fn counter(&self, counter: impl Counter) -> Option<u64> {
        self.counters.get(counter.name()).copied()
    }

    /// `gauge`, or `None` when it was never recorded.
    pub fn gauge(&self, gauge: impl Gauge) -> Option<u64> {
        self.gauges.get(gauge.name()).copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    statistics! {
        Counter:
        /// Test counters.
        enum TestCounter {
            /// Rays.
            Rays => "rays",
            /// Pixels.
            Pixels => "pixels",
            /// Not recorded.
            Missing => "missing",
        }
    }
    statistics! {
        Gauge:
        /// Test gauges.
        enum TestGauge {
            /// Bits.
            Bits => "counter-bits",
        }
    }
    statistics! {
        PhaseName:
        /// Test phases.
        enum TestPhase {
            /// A phase.
            Trace => "trace",
        }
    }

    #[test]
    fn counters_saturate_and_report() {
        let mut s = Stats::default();
        s.add(TestCounter::Rays, u64::MAX - 1);
        s.add(TestCounter::Rays, 5);
        assert_eq!(s.counter(TestCounter::Rays), Some(u64::MAX));
        assert_eq!(s.counter(TestCounter::Missing), None);
        assert_eq!(s.saturated, vec!["rays".to_string()]);
        let v = s.time(TestPhase::Trace, || 3);
        assert_eq!(v, 3);
        assert_eq!(s.phases.len(), 1);
        assert_eq!(s.device_seconds(TestPhase::Trace), None);
    }

    #[test]
    fn gauges_keep_the_largest_value_and_device_time_adds_on_merge() {
        let (mut a, mut b) = (Stats::default(), Stats::default());
        a.gauge_max(TestGauge::Bits, 16);
        a.add(TestCounter::Pixels, 3);
        a.add_time(TestPhase::Trace, 1.0);
        b.gauge_max(TestGauge::Bits, 8);
        b.add(TestCounter::Pixels, 4);
        b.add_time(TestPhase::Trace, 2.0);
        b.add_device_time(TestPhase::Trace, 0.5);
        a.add_to_bucket(TestCounter::Rays, 4, 2);
        b.add_to_bucket(TestCounter::Rays, 4, 3);
        b.add_to_bucket(TestCounter::Rays, 8, 1);
        a.merge(&b);
        let h = a.histogram(TestCounter::Rays).unwrap();
        assert_eq!((h[&4], h[&8]), (5, 1));
        assert_eq!(a.gauge(TestGauge::Bits), Some(16));
        assert_eq!(a.counter(TestCounter::Pixels), Some(7));
        assert_eq!(a.phase_seconds(TestPhase::Trace), Some(3.0));
        assert_eq!(a.device_seconds(TestPhase::Trace), Some(0.5));
        assert_eq!(a.total_device_seconds(), Some(0.5));
        let json = serde_json::to_value(&a).unwrap();
        assert_eq!(json["phases"][0]["device_seconds"], 0.5);
        assert_eq!(json["counters"]["pixels"], 7);
    }

    #[test]
    fn declared_names_are_distinct() {
        let names: Vec<&str> = CoreCounter::ALL.iter().map(|c| c.name()).collect();
        let mut sorted = names.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), names.len());
    }
}
