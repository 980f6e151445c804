//! `e^x` for many non-positive `x` at once, in plain arithmetic the compiler vectorizes.
//!
//! Monte Carlo of a Gaussian integrand spends most of its time in `exp`, one library call per
//! point that no compiler vectorizes. This is the textbook method, written as a loop of
//! additions, multiplications, compares and bit casts:
//!
//! - reduce: `x = k ln 2 + r` with `k` the nearest integer to `x / ln 2` (found by adding
//!   `1.5 · 2^52`, which rounds to an integer and leaves it in the low bits) and `|r| ≤ ln 2 / 2`,
//!   with `ln 2` split in two parts (Cody and Waite) so that `k · ln2_hi` is exact;
//! - `e^r` by its Taylor polynomial of degree 13 in Horner's form: the remainder is below
//!   `e^{0.35} 0.35^14 / 14! < 10^-17`, far below one unit in the last place;
//! - scale by `2^k`, built from its exponent bits.
//!
//! Its error is at most four units in the last place (tested against the library's `exp`).
//! Arguments below [`FLUSH_BELOW`], whose `e^x` is below the smallest normal double, give 0.
//! No fused multiply-add is used, so every machine computes the same bits, with or without
//! wide vector units.

/// Arguments below this give 0: `e^{-708}` is within a factor of 1.5 of the smallest normal
/// double, and nothing smaller matters to a sum of an integrand's values.
pub const FLUSH_BELOW: f64 = -708.0;

const LOG2_E: f64 = std::f64::consts::LOG2_E;
/// `ln 2` with the last 21 bits of its significand zero, so that `k · LN2_HI` is exact for
/// `|k| < 2^21`.
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
/// `ln 2 − LN2_HI`.
const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
/// `1.5 · 2^52`: adding it rounds to an integer, which is then in the significand's low bits.
const ROUNDER: f64 = 6_755_399_441_055_744.0;
/// `1/j!` for `j = 2 … 13`, highest first.
const INVERSE_FACTORIALS: [f64; 12] = [
    1.0 / 6_227_020_800.0,
    1.0 / 479_001_600.0,
    1.0 / 39_916_800.0,
    1.0 / 3_628_800.0,
    1.0 / 362_880.0,
    1.0 / 40_320.0,
    1.0 / 5_040.0,
    1.0 / 720.0,
    1.0 / 120.0,
    1.0 / 24.0,
    1.0 / 6.0,
    1.0 / 2.0,
];

/// Replaces each value `x ≤ 0` of `values` by `e^x` (to four units in the last place; 0 below
/// [`FLUSH_BELOW`]). Positive values are outside its domain and give meaningless results;
/// NaN stays NaN.
pub fn exp_in_place(values: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has just been found to support AVX2.
            unsafe { exp_in_place_avx2(values) };
            return;
        }
    }
    exp_loop(values);
}

/// The same loop compiled for AVX2 (four lanes instead of two); the same operations in the
/// same order, so the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn exp_in_place_avx2(values: &mut [f64]) {
    exp_loop(values);
}

#[inline(always)]
fn exp_loop(values: &mut [f64]) {
    for v in values.iter_mut() {
        *v = exp_nonpositive(*v);
    }
}

/// `e^x` for one `x ≤ 0`, as [`exp_in_place`] computes it.
#[inline(always)]
pub fn exp_nonpositive(x: f64) -> f64 {
    let flushed = x < FLUSH_BELOW;
    let x = if flushed { FLUSH_BELOW } else { x };
    let shifted = x * LOG2_E + ROUNDER;
    let k = shifted - ROUNDER;
    let r = (x - k * LN2_HI) - k * LN2_LO;
    let mut p = INVERSE_FACTORIALS[0];
    for c in &INVERSE_FACTORIALS[1..] {
        p = p * r + c;
    }
    let p = (p * r + 1.0) * r + 1.0;
    // `shifted`'s bits minus the rounder's are `k` in two's complement; `k + 1023` in the
    // exponent field is `2^k` (normal for `k ≥ −1021`, which the flush guarantees).
    let k_bits = shifted.to_bits().wrapping_sub(ROUNDER.to_bits());
    let scale = f64::from_bits(k_bits.wrapping_add(1023) << 52);
    let e = p * scale;
    if flushed {
        0.0
    } else {
        e
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest error of [`exp_in_place`] in units in the last place of the result: the
    /// reduced argument's rounding (half a unit, as a relative error of `e^r`), the
    /// polynomial's rounding in Horner's form (about two units for terms that fall off as
    /// `r^j / j!` with `|r| ≤ 0.35`), the final product's rounding (half a unit), and a unit to
    /// spare.
    const MAX_ULPS: f64 = 4.0;

    /// The distance from `a` to `b` in units in the last place of `b`.
    fn ulps(a: f64, b: f64) -> f64 {
        let unit = f64::from_bits(b.to_bits() + 1) - b;
        (a - b).abs() / unit
    }

    #[test]
    fn agrees_with_the_library_exp_to_a_few_units_in_the_last_place() {
        // Every binade of arguments from -708 to -2^-30, many points each, and the ends.
        let mut args = vec![0.0, -0.0, -1e-300, -1e-20, FLUSH_BELOW, -700.0];
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        for _ in 0..400_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let unit = (state >> 11) as f64 / (1u64 << 53) as f64;
            // Log-uniform magnitude over [2^-30, 708].
            args.push(-(2f64.powf(-30.0 + unit * (30.0 + 708f64.log2()))));
        }
        let mut values = args.clone();
        exp_in_place(&mut values);
        let worst = args
            .iter()
            .zip(&values)
            .map(|(&x, &e)| ulps(e, x.exp()))
            .fold(0.0, f64::max);
        assert!(
            worst <= MAX_ULPS,
            "worst error {worst} units in the last place"
        );
        // The scalar form is the same function.
        for (&x, &e) in args.iter().zip(&values) {
            assert_eq!(exp_nonpositive(x).to_bits(), e.to_bits(), "x = {x}");
        }
    }

    #[test]
    fn the_split_of_ln_2_is_exact_in_its_high_part_and_sums_to_ln_2() {
        assert_eq!(LN2_HI.to_bits() & ((1 << 21) - 1), 0);
        assert_eq!(LN2_HI + LN2_LO, std::f64::consts::LN_2);
        assert!((LN2_LO / std::f64::consts::LN_2).abs() < 1e-9);
    }

    #[test]
    fn below_the_smallest_normal_it_flushes_to_zero_and_nan_stays_nan() {
        let mut values = [-708.5, -1e4, f64::NEG_INFINITY, f64::NAN];
        exp_in_place(&mut values);
        assert_eq!(&values[..3], &[0.0, 0.0, 0.0]);
        assert!(values[3].is_nan());
    }
}
