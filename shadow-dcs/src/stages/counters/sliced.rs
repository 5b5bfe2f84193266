//! Bit-sliced counters: the counters of 64 light samples share `bits` words, word `b` holding bit
//! `b` of every counter, so that one update adds a mask of samples to all of them with a ripple
//! of word operations (a carry or borrow mask per bit, usually stopping after a bit or two; one
//! pass of a full adder for a weight of many bits). This is the CPU's form of the paper's
//! packing when only the zero counters are read (opaque occluders, an untextured light, a
//! visibility per sample): which samples have depth complexity zero is the complement of the
//! union of the bit words. Overflow and underflow are detected and reported, never wrapped.

use super::{Counters, OutOfRange};

/// Counters for `n` samples, `bits` bits each.
#[derive(Debug, Clone, Default)]
pub(crate) struct BitSliced {
    bits: u32,
    n: usize,
    /// Word `w * bits + b`: bit `b` of the counters of samples `64 w .. 64 w + 64`.
    planes: Vec<u64>,
}

/// One bit word of an addition: the sum and the carry out.
#[inline(always)]
fn add_step(x: u64, carry: u64) -> (u64, u64) {
    (x ^ carry, x & carry)
}

/// One bit word of a subtraction: the difference and the borrow out.
#[inline(always)]
fn sub_step(x: u64, borrow: u64) -> (u64, u64) {
    (x ^ borrow, !x & borrow)
}

/// The first `n - 64 w` bits of word `w` (the samples that exist).
#[inline]
fn valid(n: usize, w: usize) -> u64 {
    let left = n - 64 * w;
    if left >= 64 {
        u64::MAX
    } else {
        (1 << left) - 1
    }
}

impl Counters for BitSliced {
    fn reset(&mut self, bits: u32, n: usize, init: u64) -> Result<(), OutOfRange> {
        if init > super::lane_max(bits) {
            return Err(OutOfRange);
        }
        self.bits = bits;
        self.n = n;
        self.planes.clear();
        for w in 0..n.div_ceil(64) {
            let v = valid(n, w);
            self.planes
                .extend((0..bits).map(|b| if init >> b & 1 == 1 { v } else { 0 }));
        }
        Ok(())
    }

    fn add(&mut self, mask: &[u64], k: u64) -> Result<(), OutOfRange> {
        self.update(mask, k, add_step)
    }

    fn sub(&mut self, mask: &[u64], k: u64) -> Result<(), OutOfRange> {
        self.update(mask, k, sub_step)
    }

    #[inline]
    fn add_one(&mut self, mask: u64, k: u64) -> Result<(), OutOfRange> {
        self.update_word(0, mask, k, add_step)
    }

    #[inline]
    fn sub_one(&mut self, mask: u64, k: u64) -> Result<(), OutOfRange> {
        self.update_word(0, mask, k, sub_step)
    }

    /// Word by word: the words' counters are independent, so each word takes its outer
    /// updates, then its inner ones, with its bit words at hand and no loop over the words
    /// per update.
    fn apply(&mut self, words: usize, masks: &[u64], weights: &[i64]) -> Result<(), OutOfRange> {
        let top = super::lane_max(self.bits);
        if weights.iter().any(|k| k.unsigned_abs() > top) {
            return Err(OutOfRange);
        }
        let n_words = self.n.div_ceil(64).min(words);
        for w in 0..n_words {
            let cut = valid(self.n, w);
            let updates = masks.chunks_exact(words).zip(weights);
            for (m, &k) in updates.clone() {
                if k > 0 {
                    self.ripple(w, m[w] & cut, k as u64, add_step)?;
                }
            }
            for (m, &k) in updates {
                if k < 0 {
                    self.ripple(w, m[w] & cut, k.unsigned_abs(), sub_step)?;
                }
            }
        }
        Ok(())
    }
}

impl BitSliced {
    /// Adds or subtracts `k` times the samples of `mask`, word by word: the weight checked
    /// once, and only the last word cut to the samples that exist (every other word is full,
    /// so cutting it too would only cost time at large sample counts).
    #[inline]
    fn update(
        &mut self,
        mask: &[u64],
        k: u64,
        step: impl Fn(u64, u64) -> (u64, u64) + Copy,
    ) -> Result<(), OutOfRange> {
        if k > super::lane_max(self.bits) {
            return Err(OutOfRange);
        }
        let words = self.n.div_ceil(64);
        for (w, &m) in mask.iter().enumerate().take(words) {
            let m = if w + 1 == words {
                m & valid(self.n, w)
            } else {
                m
            };
            self.ripple(w, m, k, step)?;
        }
        Ok(())
    }

    /// [`BitSliced::ripple`] with the weight checked and the word cut to the samples that
    /// exist.
    #[inline(always)]
    fn update_word(
        &mut self,
        w: usize,
        m: u64,
        k: u64,
        step: impl Fn(u64, u64) -> (u64, u64),
    ) -> Result<(), OutOfRange> {
        if k > super::lane_max(self.bits) {
            return Err(OutOfRange);
        }
        self.ripple(w, m & valid(self.n, w), k, step)
    }

    /// Adds or subtracts (`step(bit word, carry) -> (new word, carry out)`) `k` (at most the
    /// counters' largest value) times the samples `m` (existing ones) of word `w`: for each
    /// set bit `b` of `k`, a ripple from bit word `b` up. Stops at the first carry out of the
    /// top bit; the counters are then partly updated, and the caller starts the pixel again.
    #[inline(always)]
    fn ripple(
        &mut self,
        w: usize,
        m: u64,
        k: u64,
        step: impl Fn(u64, u64) -> (u64, u64),
    ) -> Result<(), OutOfRange> {
        if m == 0 {
            return Ok(());
        }
        let bits = self.bits as usize;
        let planes = &mut self.planes[w * bits..(w + 1) * bits];
        if more_than_two_bits(k) {
            // A wide weight (opacity units): one pass of a full adder over the bit words from
            // the weight's lowest bit, `step` taking the weight's bit (`m` or 0) and the carry.
            let mut carry = 0u64;
            for (b, x) in planes
                .iter_mut()
                .enumerate()
                .skip(k.trailing_zeros() as usize)
            {
                let kb = if k >> b & 1 == 1 { m } else { 0 };
                if kb == 0 && carry == 0 {
                    if k >> b == 0 {
                        break;
                    }
                    continue;
                }
                // x + kb + carry (or x - kb - borrow), two half steps.
                let (y, c1) = step(*x, kb);
                let (z, c2) = step(y, carry);
                *x = z;
                carry = c1 | c2;
            }
            return if carry == 0 { Ok(()) } else { Err(OutOfRange) };
        }
        let mut todo = k;
        while todo != 0 {
            let b = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            let mut carry = m;
            for x in &mut planes[b..] {
                (*x, carry) = step(*x, carry);
                if carry == 0 {
                    break;
                }
            }
            if carry != 0 {
                return Err(OutOfRange);
            }
        }
        Ok(())
    }

    /// Appends every counter, in order, to `out` (a bit at a time: tests read them).
    #[cfg(test)]
    pub fn unpack_into(&self, out: &mut Vec<u64>) {
        let bits = self.bits as usize;
        for i in 0..self.n {
            let planes = &self.planes[(i / 64) * bits..(i / 64 + 1) * bits];
            let v = planes
                .iter()
                .enumerate()
                .fold(0u64, |v, (b, x)| v | ((x >> (i % 64)) & 1) << b);
            out.push(v);
        }
    }

    /// Sets bit `i` of `out` (whole words) for every counter `i` that is zero, clears the rest.
    pub fn zero_mask_into(&self, out: &mut [u64]) {
        let bits = self.bits as usize;
        for (w, o) in out.iter_mut().enumerate() {
            *o = if w < self.n.div_ceil(64) {
                let any = self.planes[w * bits..(w + 1) * bits]
                    .iter()
                    .fold(0, |a, x| a | x);
                !any & valid(self.n, w)
            } else {
                0
            };
        }
    }

    /// Counter `i`.
    #[cfg(test)]
    pub fn get(&self, i: usize) -> u64 {
        let mut all = Vec::new();
        self.unpack_into(&mut all);
        all[i]
    }
}

/// Whether `k` has more than two bits set: what is left once its lowest two are cleared (no
/// population count, which this target computes in software, once per update).
#[inline(always)]
fn more_than_two_bits(k: u64) -> bool {
    let above_one = k & k.wrapping_sub(1);
    above_one & above_one.wrapping_sub(1) != 0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn more_than_two_bits_counts_as_the_population_count() {
        let mut values: Vec<u64> = vec![0, 1, 2, 3, 4, 5, 6, 7, 8, u64::MAX, 1 << 63, 3 << 62];
        values.extend((0..64).flat_map(|a| (0..64).map(move |b| (1u64 << a) | (1u64 << b))));
        values.extend((0..2000u64).map(|i| i.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> (i % 64)));
        for k in values {
            assert_eq!(more_than_two_bits(k), k.count_ones() > 2, "{k:#x}");
        }
    }
    use crate::stages::counters::WIDTHS;

    #[test]
    fn zero_masks_match_the_counters() {
        for bits in WIDTHS {
            for n in [5usize, 64, 100] {
                let mut p = BitSliced::default();
                p.reset(bits, n, 1).unwrap();
                let mut plain = vec![1i64; n];
                let mut state = 99u64;
                let mut zeros = 0;
                for step in 0..20 {
                    state = shadow_core::sampling::mix64(state);
                    let mut m = [state, shadow_core::sampling::mix64(state ^ 3)];
                    let up = step % 2 == 1;
                    if !up {
                        // Only counters above zero go down (a failed update may have changed
                        // some words: the technique redoes such a pixel from the start).
                        for i in 0..n {
                            if plain[i] == 0 {
                                m[i / 64] &= !(1 << (i % 64));
                            }
                        }
                    }
                    let done = match (n, up) {
                        (64, true) => p.add_one(m[0], 1),
                        (64, false) => p.sub_one(m[0], 1),
                        (_, true) => p.add(&m, 1),
                        (_, false) => p.sub(&m, 1),
                    };
                    assert!(done.is_ok());
                    for i in 0..n {
                        if m[i / 64] >> (i % 64) & 1 == 1 {
                            plain[i] += if up { 1 } else { -1 };
                        }
                    }
                    let mut zero = [0u64; 2];
                    p.zero_mask_into(&mut zero);
                    for i in 0..128 {
                        let got = zero[i / 64] >> (i % 64) & 1 == 1;
                        assert_eq!(
                            got,
                            i < n && plain[i] == 0,
                            "bits {bits} n {n} step {step} counter {i}"
                        );
                        zeros += usize::from(got);
                    }
                }
                assert!(zeros > 0, "bits {bits} n {n}: no zero reached");
            }
        }
    }

    #[test]
    fn overflow_and_underflow_are_detected_not_wrapped() {
        let mut p = BitSliced::default();
        crate::stages::counters::check_range_errors(&mut p, |p, i| p.get(i));
        // Wide weights down and up (one pass of a full adder), many words.
        p.reset(16, 100, 1000).unwrap();
        let m = [0xf0f0_f0f0_0f0f_0f0f, 0xffff_0000_ffff];
        p.sub(&m, 255).unwrap();
        p.sub(&m, 745).unwrap();
        p.add(&m, 7).unwrap();
        for i in 0..100 {
            let hit = m[i / 64] >> (i % 64) & 1 == 1;
            assert_eq!(p.get(i), if hit { 7 } else { 1000 }, "counter {i}");
        }
        assert_eq!(p.sub(&m, 255), Err(OutOfRange));
        // A weight wider than the counters is out of range too.
        p.reset(8, 4, 0).unwrap();
        assert_eq!(p.add(&[1], 256), Err(OutOfRange));
    }
}
