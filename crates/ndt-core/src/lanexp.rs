//! `exp(x)` for `x ≤ 0`, written without branches or table look-ups so that
//! a loop over a block of pairs compiles to SIMD instructions (the score of
//! eq. 1 takes one `exp` per pair). The C library's `exp` is a call per value
//! and keeps the loop scalar.
//!
//! Method (as in Cephes and fdlibm): `x = n ln 2 + r` with `n` the nearest
//! integer to `x / ln 2` and `|r| ≤ ln 2 / 2`; `exp(r)` by its Taylor
//! polynomial of degree 13 (truncation error below 5e-18 relative); the result
//! `2ⁿ exp(r)`, with `2ⁿ` built in the exponent bits. Only `+`, `−`, `×` are
//! used, never a fused multiply-add, so every instruction set rounds alike and
//! the result does not depend on the processor it runs on. Within 2 ulp of
//! the correctly rounded value on `[−708, 0]` (tested against `f64::exp`).

/// Below this, [`exp_nonpositive`] returns 0: `exp(−708)` ≈ 3.3e-308 is
/// the smallest value kept normal (anything smaller is not worth a term).
pub const EXP_MIN_ARG: f64 = -708.0;

/// `1.5 · 2⁵²`: adding it rounds to an integer held in the low mantissa bits.
const SHIFT: f64 = 6_755_399_441_055_744.0;
const LOG2_E: f64 = std::f64::consts::LOG2_E;
/// `ln 2` split so that `n · LN2_HI` is exact for `|n| < 2¹¹` (fdlibm).
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
/// `1 / k!` for `k = 13, 12, …, 2` (Horner order).
const INV_FACT: [f64; 12] = [
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
    0.5,
];

/// `exp(x)` for `x ∈ [EXP_MIN_ARG, 0]`; 0 below [`EXP_MIN_ARG`] and for
/// NaN (a pair whose term is to be dropped). Arguments above 0 are clamped
/// to 0 (the score's exponent `−½ dᵀ C d` is never positive but for
/// rounding). Branch-free: inlined into a loop it vectorises.
#[inline(always)]
pub fn exp_nonpositive(x: f64) -> f64 {
    // NaN fails both comparisons and ends up dropped.
    let keep = x >= EXP_MIN_ARG;
    let x = if keep { x.min(0.0) } else { EXP_MIN_ARG };
    let kd = x * LOG2_E + SHIFT;
    let n = kd - SHIFT;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    let mut p = INV_FACT[0];
    for c in &INV_FACT[1..] {
        p = p * r + c;
    }
    let p = (p * r + 1.0) * r + 1.0;
    // kd's low bits hold n (two's complement): 2ⁿ has exponent field n + 1023
    // (in [1, 1023] for x ≥ −708).
    let two_n = f64::from_bits(kd.to_bits().wrapping_add(1023) << 52);
    if keep {
        p * two_n
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// Distance in units in the last place.
    fn ulps(a: f64, b: f64) -> u64 {
        (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs()
    }

    #[test]
    fn within_two_ulp_of_libm() {
        let mut rng = StdRng::seed_from_u64(5);
        let mut worst = 0;
        let mut check = |x: f64| {
            let u = ulps(exp_nonpositive(x), x.exp());
            assert!(
                u <= 2,
                "exp({x:e}): {} vs {} ({u} ulp)",
                exp_nonpositive(x),
                x.exp()
            );
            worst = worst.max(u);
        };
        for _ in 0..1_000_000 {
            check(rng.random_range(-40.0..=0.0));
        }
        for _ in 0..200_000 {
            check(rng.random_range(EXP_MIN_ARG..=0.0));
        }
        for _ in 0..200_000 {
            check(-rng.random_range(0.0f64..1e-3));
        }
        // Half-way points of the reduction and the ends of the range.
        for k in 0..=1021 {
            let x = -(k as f64) * std::f64::consts::LN_2;
            for dx in [-1e-12, 0.0, 1e-12] {
                if x + dx <= 0.0 && x + dx >= EXP_MIN_ARG {
                    check(x + dx);
                }
            }
            let h = -(k as f64 + 0.5) * std::f64::consts::LN_2;
            if h >= EXP_MIN_ARG {
                check(h);
            }
        }
        for x in [
            0.0,
            -0.0,
            -1e-300,
            f64::MIN_POSITIVE.copysign(-1.0),
            EXP_MIN_ARG,
        ] {
            check(x);
        }
        assert!(worst <= 2);
    }

    #[test]
    fn edges() {
        assert_eq!(exp_nonpositive(0.0), 1.0);
        assert_eq!(exp_nonpositive(-0.0), 1.0);
        // Rounding can leave the score's exponent a hair above 0.
        assert_eq!(exp_nonpositive(1e-17), 1.0);
        assert_eq!(exp_nonpositive(-708.5), 0.0);
        assert_eq!(exp_nonpositive(f64::NEG_INFINITY), 0.0);
        assert_eq!(exp_nonpositive(f64::NAN), 0.0);
        assert!(exp_nonpositive(EXP_MIN_ARG) > 0.0);
    }
}
