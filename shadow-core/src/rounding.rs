//! `floor` and `ceil` without a library call. The baseline x86-64 target has no rounding
//! instruction (SSE4.1's `roundss` is not in it), so `f32::floor` and `f64::ceil` compile to
//! calls into the C library; in per-texel and per-row code those calls cost more than the
//! arithmetic around them. Truncation through `i64` rounds toward zero, and one step fixes the
//! direction. The results equal the library's in value for every input (a zero may come out
//! with the other sign): above `2^23` (`f32`) or `2^52` (`f64`) every value is an integer, which
//! the round trip keeps, and values too large for `i64` take the library call, as do
//! infinities and NaN.

/// Largest magnitude that goes through `i64` (below `2^63`, with room to spare).
const THROUGH_I64: f64 = 9.0e18;

/// `x.floor()`: the floor of a float is a float, so the double-precision one is exact.
#[inline]
pub(crate) fn floor_f32(x: f32) -> f32 {
    floor_f64(f64::from(x)) as f32
}

/// `x.floor()`.
#[inline]
pub(crate) fn floor_f64(x: f64) -> f64 {
    if x.abs() < THROUGH_I64 {
        let t = x as i64 as f64;
        if t > x { t - 1.0 } else { t }
    } else {
        x.floor()
    }
}

/// `x.ceil()`.
#[inline]
pub(crate) fn ceil_f64(x: f64) -> f64 {
    if x.abs() < THROUGH_I64 {
        let t = x as i64 as f64;
        if t < x { t + 1.0 } else { t }
    } else {
        x.ceil()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Equal in value to the library's results on fractions, integers, signed zeros, the edges of the
    /// exactly representable integers, huge values, infinities and NaN, and on a sweep.
    #[test]
    fn rounding_equals_the_library() {
        let specials = [
            0.0,
            -0.0,
            0.5,
            -0.5,
            -1.0,
            1.0,
            2.75,
            -2.75,
            8388607.5,
            -8388609.0,
            4.5e15 + 0.5,
            -4.5e15 - 0.5,
            9.007e15,
            1e20,
            -1e20,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let sweep = (0..20_000).map(|k| (k as f64 - 10_000.0) * 0.013_7);
        for x in specials.into_iter().chain(sweep) {
            assert_eq!(floor_f64(x), x.floor(), "floor {x}");
            assert_eq!(ceil_f64(x), x.ceil(), "ceil {x}");
            let xf = x as f32;
            assert_eq!(floor_f32(xf), xf.floor(), "floor {xf}");
        }
        assert!(floor_f64(f64::NAN).is_nan() && ceil_f64(f64::NAN).is_nan());
        assert!(floor_f32(f32::NAN).is_nan());
    }
}
