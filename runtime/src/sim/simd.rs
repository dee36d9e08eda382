//! Eight lanes at once, one per IR sensor: the only module of the workspace
//! with `unsafe` code.
//!
//! The per-sensor loops of the simulator (walls', objects' and lamps'
//! readings) are written once, over a [`Lanes`] value of 8 `f32`, in a
//! [`Kernel`]. [`run`] runs a kernel on AVX2 registers when the CPU has them
//! (detected at run time, so one binary runs on any x86-64) and on plain
//! arrays otherwise ([`Portable`]; LLVM vectorises its loops with SSE).
//!
//! Both paths give the same bits: every lane operation is one IEEE-754
//! operation rounded once (add, sub, mul, div, sqrt, comparisons), in the
//! same order, with the same NaN rules (`max`/`min` return the second
//! operand unless the first is strictly greater/smaller, as `vmaxps` and
//! `vminps` do). Fused multiply-add is used in neither path: it rounds once
//! where a multiply then an add round twice, and a portable path without
//! FMA hardware would have to emulate it slowly. So a seed gives the same
//! trajectory on a machine with AVX2 as on one without.

#![allow(unsafe_code)]

use super::ir::{SatTable, SENSORS, TABLE_LEN};

/// 8 `f32` lanes and the operations the kernels use.
pub(crate) trait Lanes: Copy {
    fn splat(x: f32) -> Self;
    fn load(a: &[f32; SENSORS]) -> Self;
    fn store(self, a: &mut [f32; SENSORS]);
    fn add(self, o: Self) -> Self;
    fn sub(self, o: Self) -> Self;
    fn mul(self, o: Self) -> Self;
    fn div(self, o: Self) -> Self;
    fn sqrt(self) -> Self;
    /// `self` where `self > o`, else `o` (so `o` when either is NaN).
    fn max(self, o: Self) -> Self;
    /// `self` where `self < o`, else `o` (so `o` when either is NaN).
    fn min(self, o: Self) -> Self;
    /// The table's value at `t`, interpolated linearly; `t` in
    /// `0..=TABLE_LEN - 1` (not NaN).
    fn lerp(self, table: &[f32; TABLE_LEN + 1]) -> Self;
}

/// [`SatTable::get`] of every lane: the same operations in the same order.
#[inline(always)]
pub(crate) fn saturate<L: Lanes>(z: L, table: &SatTable) -> L {
    let (z_min, scale) = SatTable::SCALE;
    let t = z.sub(L::splat(z_min)).mul(L::splat(scale));
    // max first: a NaN becomes 0, in range for the lookup.
    let t = t.max(L::splat(0.0)).min(L::splat((TABLE_LEN - 1) as f32));
    t.lerp(table.values())
}

/// Plain arrays: the path on CPUs without AVX2.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Portable([f32; SENSORS]);

impl Portable {
    #[inline(always)]
    fn zip(self, o: Portable, f: impl Fn(f32, f32) -> f32) -> Portable {
        let mut r = [0.0; SENSORS];
        for k in 0..SENSORS {
            r[k] = f(self.0[k], o.0[k]);
        }
        Portable(r)
    }
}

impl Lanes for Portable {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        Portable([x; SENSORS])
    }
    #[inline(always)]
    fn load(a: &[f32; SENSORS]) -> Self {
        Portable(*a)
    }
    #[inline(always)]
    fn store(self, a: &mut [f32; SENSORS]) {
        *a = self.0;
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        self.zip(o, |a, b| a + b)
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        self.zip(o, |a, b| a - b)
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        self.zip(o, |a, b| a * b)
    }
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        self.zip(o, |a, b| a / b)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Portable(self.0.map(f32::sqrt))
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        self.zip(o, |a, b| if a > b { a } else { b })
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        self.zip(o, |a, b| if a < b { a } else { b })
    }
    #[inline(always)]
    fn lerp(self, table: &[f32; TABLE_LEN + 1]) -> Self {
        Portable(self.0.map(|t| {
            let i = (t as usize).min(TABLE_LEN - 1);
            let f = t - i as f32;
            table[i] + (table[i + 1] - table[i]) * f
        }))
    }
}

/// A computation over the 8 sensors, generic in how lanes are computed.
pub(crate) trait Kernel {
    type Out;
    /// Mark implementations `#[inline(always)]`, so that the AVX2 path
    /// compiles their body with AVX2.
    fn run<L: Lanes>(self) -> Self::Out;
}

/// Which path [`run`] takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Path {
    /// AVX2 where the CPU has it, else portable.
    Best,
    /// Portable, whatever the CPU (for tests comparing the paths).
    Portable,
}

/// Runs `k` on the best lanes this CPU has (or the portable ones).
#[inline(always)]
pub(crate) fn run<K: Kernel>(k: K, path: Path) -> K::Out {
    #[cfg(target_arch = "x86_64")]
    if path == Path::Best && avx::available() {
        // SAFETY: the CPU has AVX2 (checked just above), the only feature
        // `run_avx2` enables.
        return unsafe { avx::run_avx2(k) };
    }
    let _ = path;
    k.run::<Portable>()
}

/// True when [`run`] with [`Path::Best`] takes the AVX2 path here.
pub fn avx2_in_use() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        avx::available()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

#[cfg(target_arch = "x86_64")]
mod avx {
    use super::{Kernel, Lanes, SENSORS, TABLE_LEN};
    use std::arch::x86_64::*;

    #[inline(always)]
    pub(super) fn available() -> bool {
        is_x86_feature_detected!("avx2")
    }

    /// Lanes in an AVX register. Values of this type exist only inside
    /// [`run_avx2`], which runs only on CPUs with AVX2: that is what makes
    /// the intrinsics below sound. Private, so no other code can make one.
    #[derive(Clone, Copy)]
    pub(super) struct Avx(__m256);

    /// # Safety
    /// The CPU must support AVX2.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn run_avx2<K: Kernel>(k: K) -> K::Out {
        k.run::<Avx>()
    }

    impl Lanes for Avx {
        #[inline(always)]
        fn splat(x: f32) -> Self {
            // SAFETY: an `Avx` exists only on CPUs with AVX2 (see the type).
            Avx(unsafe { _mm256_set1_ps(x) })
        }
        #[inline(always)]
        fn load(a: &[f32; SENSORS]) -> Self {
            // SAFETY: AVX2 (see the type); `a` is 8 readable f32, and the
            // load is unaligned.
            Avx(unsafe { _mm256_loadu_ps(a.as_ptr()) })
        }
        #[inline(always)]
        fn store(self, a: &mut [f32; SENSORS]) {
            // SAFETY: AVX2 (see the type); `a` is 8 writable f32, and the
            // store is unaligned.
            unsafe { _mm256_storeu_ps(a.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            // SAFETY: AVX2 (see the type).
            Avx(unsafe { _mm256_add_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn sub(self, o: Self) -> Self {
            // SAFETY: AVX2 (see the type).
            Avx(unsafe { _mm256_sub_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            // SAFETY: AVX2 (see the type).
            Avx(unsafe { _mm256_mul_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn div(self, o: Self) -> Self {
            // SAFETY: AVX2 (see the type).
            Avx(unsafe { _mm256_div_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            // SAFETY: AVX2 (see the type).
            Avx(unsafe { _mm256_sqrt_ps(self.0) })
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            // SAFETY: AVX2 (see the type). vmaxps returns its second operand
            // unless the first is greater, like the portable max.
            Avx(unsafe { _mm256_max_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            // SAFETY: AVX2 (see the type); vminps likewise.
            Avx(unsafe { _mm256_min_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn lerp(self, table: &[f32; TABLE_LEN + 1]) -> Self {
            // SAFETY: AVX2 (see the type). The lanes are in
            // `0..=TABLE_LEN - 1` (the caller's contract), so the truncated
            // indices `i` are too and `i + 1 <= TABLE_LEN`: both gathers
            // read inside `table`, which has `TABLE_LEN + 1` values.
            unsafe {
                let t = self.0;
                let i = _mm256_cvttps_epi32(t);
                let f = _mm256_sub_ps(t, _mm256_cvtepi32_ps(i));
                let base = table.as_ptr();
                let lo = _mm256_i32gather_ps::<4>(base, i);
                let hi = _mm256_i32gather_ps::<4>(base, _mm256_add_epi32(i, _mm256_set1_epi32(1)));
                Avx(_mm256_add_ps(lo, _mm256_mul_ps(_mm256_sub_ps(hi, lo), f)))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every lane operation on awkward values (zeros of both signs,
    /// infinities, NaN, tiny and huge numbers), on both paths.
    struct Ops([f32; SENSORS], [f32; SENSORS]);

    impl Kernel for Ops {
        type Out = Vec<[f32; SENSORS]>;
        #[inline(always)]
        fn run<L: Lanes>(self) -> Self::Out {
            let (a, b) = (L::load(&self.0), L::load(&self.1));
            let table = super::super::ir::tables().0.values();
            let t = a.max(L::splat(0.0)).min(L::splat((TABLE_LEN - 1) as f32));
            let results =
                [a.add(b), a.sub(b), a.mul(b), a.div(b), a.sqrt(), a.max(b), a.min(b), t.lerp(table)];
            results
                .iter()
                .map(|r| {
                    let mut out = [0.0; SENSORS];
                    r.store(&mut out);
                    out
                })
                .collect()
        }
    }

    #[test]
    fn both_paths_give_the_same_bits() {
        let odd = [0.0, -0.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 1e-40, 3.0e38, -1.5];
        let mut inputs = vec![(odd, odd.map(|x| -x))];
        let mut x = 0.37f32;
        for _ in 0..200 {
            let mut a = [0.0; SENSORS];
            let mut b = [0.0; SENSORS];
            for k in 0..SENSORS {
                x = (x * 997.13 + 0.71).fract();
                a[k] = (x - 0.3) * 1100.0;
                x = (x * 991.7 + 0.29).fract();
                b[k] = (x - 0.5) * 40.0;
            }
            inputs.push((a, b));
            inputs.push((odd, a));
        }
        for (a, b) in inputs {
            let best = run(Ops(a, b), Path::Best);
            let portable = run(Ops(a, b), Path::Portable);
            // Bits, every NaN as one (which operand's NaN an add passes on
            // is not part of the contract; the simulator makes none).
            let bits = |v: &Vec<[f32; SENSORS]>| {
                v.iter()
                    .map(|r| r.map(|x| if x.is_nan() { u32::MAX } else { x.to_bits() }))
                    .collect::<Vec<_>>()
            };
            assert_eq!(bits(&best), bits(&portable), "{a:?} {b:?}");
        }
        eprintln!("AVX2 path in use: {}", avx2_in_use());
    }

    #[test]
    fn the_lanes_lookup_is_the_tables() {
        let table = &super::super::ir::tables().1;
        for i in -200..=200 {
            let z = i as f32 * 0.061;
            let mut out = [0.0; SENSORS];
            struct Sat(f32);
            impl Kernel for Sat {
                type Out = [f32; SENSORS];
                #[inline(always)]
                fn run<L: Lanes>(self) -> [f32; SENSORS] {
                    let mut o = [0.0; SENSORS];
                    saturate(L::splat(self.0), &super::super::ir::tables().1).store(&mut o);
                    o
                }
            }
            for path in [Path::Best, Path::Portable] {
                out = run(Sat(z), path);
                assert!(out.iter().all(|&v| v == table.get(z)), "{z}: {out:?}");
            }
            assert!(out[0] >= 0.0 && out[0] <= 1.0);
        }
    }
}
