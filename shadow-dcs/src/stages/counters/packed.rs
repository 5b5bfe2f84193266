//! The paper's packing (DCS sections 4.3 and 4.4, Fig. 3): several unsigned counters share a
//! 64-bit word (8 of 8 bits, 4 of 16 bits or 2 of 32 bits) and one word addition updates all of
//! them. An update that would carry out of a lane (overflow) or borrow into one (underflow) is
//! detected with SWAR carry logic and reported, never wrapped. Reading the counters back costs
//! a shift and a mask each, which suits pixels whose every depth complexity is read (semi-opaque
//! occluders, textured lights, per-sample counters).

use super::{Counters, OutOfRange};

/// Counters for `n` samples in lanes of `bits` bits.
#[derive(Debug, Clone, Default)]
pub(crate) struct Packed {
    bits: u32,
    n: usize,
    words: Vec<u64>,
}

/// `0x0101...01` (one in the lowest bit of each lane) for a lane width.
fn ones(bits: u32) -> u64 {
    match bits {
        8 => 0x0101_0101_0101_0101,
        16 => 0x0001_0001_0001_0001,
        _ => 0x0000_0001_0000_0001,
    }
}

/// Bit `i` of a byte moved to bit `8 i` (the 8-bit lane increments of Fig. 3).
const SPREAD8: [u64; 256] = {
    let mut t = [0u64; 256];
    let mut m = 0;
    while m < 256 {
        let mut i = 0;
        while i < 8 {
            t[m] |= ((m as u64 >> i) & 1) << (8 * i);
            i += 1;
        }
        m += 1;
    }
    t
};

/// Spreads the low `64 / bits` bits of `m` to the lowest bit of each lane.
#[inline]
fn spread(m: u64, bits: u32) -> u64 {
    match bits {
        8 => SPREAD8[(m & 0xff) as usize],
        16 => (m & 1) | (((m >> 1) & 1) << 16) | (((m >> 2) & 1) << 32) | (((m >> 3) & 1) << 48),
        _ => (m & 1) | (((m >> 1) & 1) << 32),
    }
}

impl Counters for Packed {
    fn reset(&mut self, bits: u32, n: usize, init: u64) -> Result<(), OutOfRange> {
        if init > super::lane_max(bits) {
            return Err(OutOfRange);
        }
        self.bits = bits;
        self.n = n;
        let lanes = (64 / bits) as usize;
        self.words.clear();
        self.words.resize(n.div_ceil(lanes), init * ones(bits));
        Ok(())
    }

    fn add(&mut self, mask: &[u64], k: u64) -> Result<(), OutOfRange> {
        self.update(mask, k, |x, y, high, low| {
            let s = ((x & low) + (y & low)) ^ ((x ^ y) & high);
            // Carry out of each lane's top bit.
            (s, ((x & y) | ((x | y) & !s)) & high)
        })
    }

    fn sub(&mut self, mask: &[u64], k: u64) -> Result<(), OutOfRange> {
        self.update(mask, k, |x, y, high, low| {
            let d = ((x | high) - (y & low)) ^ ((x ^ !y) & high);
            // Borrow out of each lane's top bit.
            (d, ((!x & y) | (!(x ^ y) & d)) & high)
        })
    }
}

impl Packed {
    /// Lane mask of word `w` taken from the sample bit mask.
    #[inline]
    fn lane_bits(&self, mask: &[u64], w: usize) -> u64 {
        let lanes = 64 / self.bits as usize;
        let first = w * lanes;
        (mask[first / 64] >> (first % 64)) & ((1u64 << lanes) - 1)
    }

    /// Applies a lane-wise operation `op(x, y, high, low) -> (result, out-of-range lanes)` with
    /// `y` holding `k` in the lanes `mask` selects; stops at the first word that leaves range.
    #[inline]
    fn update(
        &mut self,
        mask: &[u64],
        k: u64,
        op: impl Fn(u64, u64, u64, u64) -> (u64, u64),
    ) -> Result<(), OutOfRange> {
        if k > super::lane_max(self.bits) {
            return Err(OutOfRange);
        }
        let high = ones(self.bits) << (self.bits - 1);
        let low = !high;
        for w in 0..self.words.len() {
            let m = self.lane_bits(mask, w);
            if m == 0 {
                continue;
            }
            let (r, out) = op(self.words[w], spread(m, self.bits) * k, high, low);
            if out != 0 {
                return Err(OutOfRange);
            }
            self.words[w] = r;
        }
        Ok(())
    }

    /// Appends every counter, in order, to `out` (lane by lane, without a division each).
    pub fn unpack_into(&self, out: &mut Vec<u64>) {
        let lanes = (64 / self.bits) as usize;
        let max = super::lane_max(self.bits);
        let mut left = self.n;
        for &w in &self.words {
            let take = left.min(lanes);
            out.extend((0..take).map(|j| (w >> (j as u32 * self.bits)) & max));
            left -= take;
        }
    }

    /// Counter `i`.
    #[cfg(test)]
    pub fn get(&self, i: usize) -> u64 {
        let lanes = (64 / self.bits) as usize;
        (self.words[i / lanes] >> ((i % lanes) as u32 * self.bits)) & super::lane_max(self.bits)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stages::counters::WIDTHS;

    #[test]
    fn spread_puts_each_bit_in_its_lane() {
        for m in 0..256u64 {
            let s = spread(m, 8);
            for i in 0..8 {
                assert_eq!((s >> (8 * i)) & 0xff, (m >> i) & 1, "{m} {i}");
            }
        }
        for m in 0..16u64 {
            let s = spread(m, 16);
            for i in 0..4 {
                assert_eq!((s >> (16 * i)) & 0xffff, (m >> i) & 1);
            }
        }
    }

    #[test]
    fn packed_updates_match_plain_counters() {
        for bits in WIDTHS {
            let n = 100;
            let mut p = Packed::default();
            p.reset(bits, n, 3).unwrap();
            let mut plain = vec![3u64; n];
            let mut state = 12345u64;
            for step in 0..50 {
                state = shadow_core::sampling::mix64(state);
                let mask = [state, shadow_core::sampling::mix64(state ^ 7)];
                let k = 1 + step % 3;
                p.add(&mask, k).unwrap();
                for i in 0..n {
                    if mask[i / 64] >> (i % 64) & 1 == 1 {
                        plain[i] += k;
                    }
                }
            }
            for i in 0..n {
                assert_eq!(p.get(i), plain[i], "bits {bits} counter {i}");
            }
            let mut all = Vec::new();
            p.unpack_into(&mut all);
            assert_eq!(all, plain, "bits {bits}: unpacked");
        }
    }

    #[test]
    fn overflow_and_underflow_are_detected_not_wrapped() {
        let mut p = Packed::default();
        crate::stages::counters::check_range_errors(&mut p, |p, i| p.get(i));
        p.reset(8, 16, 250).unwrap();
        let mask = [0b10u64];
        p.add(&mask, 5).unwrap();
        assert_eq!(p.add(&mask, 1), Err(OutOfRange));
        // The failed update left every counter as it was.
        assert_eq!(p.get(1), 255);
        assert_eq!(p.get(0), 250);
    }
}
