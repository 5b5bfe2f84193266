//! Device time of compute passes from timestamp queries (wgpu's `TIMESTAMP_QUERY`), where the
//! adapter has them: the time the passes ran on the device, without the submission, the wait
//! and the readbacks that wall-clock phase times include.
//!
//! Each [`Encoder`] carries its own query set, so encoders recorded by different threads never
//! share query slots. [`crate::gpu::GpuContext::submit`] resolves the slots an encoder used,
//! reads them back once the work is done and adds the passes' durations to the context's
//! running total, which [`crate::gpu::GpuContext::take_device_seconds`] returns and clears.

use std::ops::{Deref, DerefMut};

/// Queries per encoder: a begin and an end per pass. Passes beyond `CAPACITY / 2` run
/// untimed, and the encoder then reports no device time rather than a partial one.
pub(crate) const CAPACITY: u32 = 64;

/// A command encoder with, where the device has timestamp queries, a query set its compute
/// passes write their begin and end times to. It dereferences to the wgpu encoder.
pub struct Encoder {
    pub(crate) inner: wgpu::CommandEncoder,
    pub(crate) queries: Option<Queries>,
}

/// An encoder's query set and how far it is used.
pub(crate) struct Queries {
    pub(crate) set: wgpu::QuerySet,
    pub(crate) used: u32,
    pub(crate) untimed: bool,
}

impl Queries {
    /// The timestamp writes for the next compute pass (none once the set is full).
    pub(crate) fn next_pass(&mut self) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let q = self;
        if q.used + 2 > CAPACITY {
            q.untimed = true;
            return None;
        }
        let begin = q.used;
        q.used += 2;
        Some(wgpu::ComputePassTimestampWrites {
            query_set: &q.set,
            beginning_of_pass_write_index: Some(begin),
            end_of_pass_write_index: Some(begin + 1),
        })
    }
}

impl Deref for Encoder {
    type Target = wgpu::CommandEncoder;
    fn deref(&self) -> &Self::Target {
        &self.inner
    }
}

impl DerefMut for Encoder {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.inner
    }
}

/// Seconds between each pass's begin and end stamps (`ticks` in begin, end pairs), summed;
/// stamps that run backwards (a device that does not order them) count as zero.
pub(crate) fn pass_seconds(ticks: &[u64], period_ns: f32) -> f64 {
    ticks
        .chunks_exact(2)
        .map(|p| p[1].saturating_sub(p[0]) as f64)
        .sum::<f64>()
        * period_ns as f64
        * 1e-9
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pass_seconds_sums_each_pass_and_ignores_backward_stamps() {
        // Two passes of 1000 and 500 ticks at 2 ns, one with its stamps reversed.
        let s = pass_seconds(&[10, 1010, 2000, 2500, 90, 80], 2.0);
        assert!((s - 3.0e-6).abs() < 1e-15, "{s}");
        assert_eq!(pass_seconds(&[], 1.0), 0.0);
    }
}
