//! Packed depth-complexity counters (DCS sections 4.3, 4.4 and 5.3): one unsigned counter per
//! light sample, many sharing a machine word, updated by a whole mask of samples at once. The
//! precision is chosen per frame from the largest integration constant (section 5.3); an update
//! that would leave the counters' range is detected and reported, never wrapped, and the caller
//! redoes the pixel with wider counters (or, past the widest, plain signed ones).
//!
//! Two packings share that contract:
//! * `Packed`: the paper's (Fig. 3), several counters in the lanes of a word, one addition
//!   each; reading a counter back is a shift and a mask;
//! * `BitSliced`: bit `b` of 64 counters in one word, an update a ripple of word operations;
//!   the zero counters (the visible samples) come out as one mask.
//!
//! The technique takes the bit-sliced form when it needs only which samples are visible and the
//! paper's form when it reads every depth complexity.

mod packed;
mod sliced;

pub(crate) use packed::Packed;
pub(crate) use sliced::BitSliced;

/// An update would leave the counters' range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct OutOfRange;

/// Counter precisions tried in turn (bits), the narrowest first.
pub(crate) const WIDTHS: [u32; 3] = [8, 16, 32];

/// Largest value a counter of `bits` bits holds.
pub(crate) fn lane_max(bits: u32) -> u64 {
    if bits >= 64 {
        u64::MAX
    } else {
        (1u64 << bits) - 1
    }
}

/// The narrowest precision of [`WIDTHS`] whose range holds twice `max_constant` (section 5.3,
/// with headroom for penumbra samples deeper than the centre).
pub(crate) fn width_for(max_constant: u64) -> u32 {
    WIDTHS
        .into_iter()
        .find(|&b| max_constant.saturating_mul(2) < lane_max(b))
        .unwrap_or(32)
}

/// What the update loop needs of a packing.
pub(crate) trait Counters {
    /// `n` counters of `bits` bits, all holding `init`.
    fn reset(&mut self, bits: u32, n: usize, init: u64) -> Result<(), OutOfRange>;
    /// Adds `k` to every counter whose bit is set in `mask`.
    fn add(&mut self, mask: &[u64], k: u64) -> Result<(), OutOfRange>;
    /// Subtracts `k` from every counter whose bit is set in `mask`.
    fn sub(&mut self, mask: &[u64], k: u64) -> Result<(), OutOfRange>;
    /// [`Counters::add`] for counters that fit one word of samples.
    fn add_one(&mut self, mask: u64, k: u64) -> Result<(), OutOfRange> {
        self.add(&[mask], k)
    }
    /// [`Counters::sub`] for counters that fit one word of samples.
    fn sub_one(&mut self, mask: u64, k: u64) -> Result<(), OutOfRange> {
        self.sub(&[mask], k)
    }
    /// Every update of more than one word of samples (`masks`, `words` per update, and their
    /// weights), outer wedges (`k > 0`) before inner ones: update by update, each over all
    /// the words, unless the packing has a better order.
    fn apply(&mut self, words: usize, masks: &[u64], weights: &[i64]) -> Result<(), OutOfRange> {
        for outer in [true, false] {
            for (m, &k) in masks.chunks(words).zip(weights) {
                if (k > 0) != outer {
                    continue;
                }
                if k > 0 {
                    self.add(m, k as u64)?;
                } else {
                    self.sub(m, k.unsigned_abs())?;
                }
            }
        }
        Ok(())
    }
}

/// Applies the updates (`masks`, `words` per update, and their weights) to counters of `bits`
/// bits starting at `d0`, outer wedges (`k > 0`) before inner ones (section 4.4), so that no
/// counter dips below zero on the way to a final value that does not.
pub(crate) fn run<C: Counters>(
    counters: &mut C,
    bits: u32,
    n: usize,
    d0: u64,
    masks: &[u64],
    weights: &[i64],
) -> Result<(), OutOfRange> {
    counters.reset(bits, n, d0)?;
    let words = n.div_ceil(64);
    if words == 1 {
        for (&m, &k) in masks.iter().zip(weights) {
            if k > 0 {
                counters.add_one(m, k as u64)?;
            }
        }
        for (&m, &k) in masks.iter().zip(weights) {
            if k < 0 {
                counters.sub_one(m, k.unsigned_abs())?;
            }
        }
        return Ok(());
    }
    counters.apply(words, masks, weights)
}

/// The range checks every packing must pass, `get` reading counter `i`: an add past the top
/// and a subtraction below zero fail, and an initial value too wide for the counters is refused.
#[cfg(test)]
pub(crate) fn check_range_errors<C: Counters>(c: &mut C, get: impl Fn(&C, usize) -> u64) {
    c.reset(8, 16, 250).unwrap();
    let mask = [0b10u64];
    c.add(&mask, 5).unwrap();
    assert_eq!(get(c, 1), 255);
    assert_eq!(c.add(&mask, 1), Err(OutOfRange));
    c.reset(16, 8, 1).unwrap();
    c.sub(&[0b100], 1).unwrap();
    assert_eq!(get(c, 2), 0);
    assert_eq!(c.sub(&[0b100], 1), Err(OutOfRange));
    assert_eq!(get(c, 3), 1);
    assert!(c.reset(8, 4, 256).is_err());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widths_hold_twice_the_largest_constant() {
        assert_eq!(width_for(10), 8);
        assert_eq!(width_for(200), 16);
        assert_eq!(width_for(40_000), 32);
        assert_eq!(width_for(u64::MAX / 2), 32);
    }

    /// Both packings give the same counters and the same errors for the same updates (the
    /// bit-sliced form takes many words word by word, the paper's form update by update),
    /// with weights that overflow narrow counters, weights wider than any counter, and
    /// weights that stay in range.
    #[test]
    fn both_packings_agree() {
        let (mut state, mut oks) = (5u64, 0);
        let patterns: [&[i64]; 3] = [&[1, -1, 3, 255, -2], &[1, -1, 2, -1, 1], &[2, 1, -1, 70000]];
        for n in [16usize, 64, 100, 256, 300] {
            for (bits, pattern) in WIDTHS.into_iter().flat_map(|b| patterns.map(|p| (b, p))) {
                let words = n.div_ceil(64);
                let (mut masks, mut weights) = (Vec::new(), Vec::new());
                for step in 0..40 {
                    state = shadow_core::sampling::mix64(state);
                    for w in 0..words {
                        masks.push(shadow_core::sampling::mix64(state ^ w as u64));
                    }
                    weights.push(pattern[step % pattern.len()]);
                }
                let (mut p, mut s) = (Packed::default(), BitSliced::default());
                let d0 = if bits == 8 { 40 } else { 600 };
                let a = run(&mut p, bits, n, d0, &masks, &weights);
                let b = run(&mut s, bits, n, d0, &masks, &weights);
                assert_eq!(a, b, "n {n} bits {bits} weights {pattern:?}");
                oks += usize::from(a.is_ok());
                if a.is_ok() {
                    let (mut x, mut y) = (Vec::new(), Vec::new());
                    p.unpack_into(&mut x);
                    s.unpack_into(&mut y);
                    assert_eq!(x, y, "n {n} bits {bits}");
                    let mut zero = vec![0u64; words];
                    s.zero_mask_into(&mut zero);
                    for i in 0..n {
                        assert_eq!(zero[i / 64] >> (i % 64) & 1 == 1, x[i] == 0);
                    }
                }
            }
        }
        // Both outcomes were met: ranges kept and ranges left.
        assert!(oks > 5 && oks < 40, "{oks} of 45 runs in range");
    }
}
