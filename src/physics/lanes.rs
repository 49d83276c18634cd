//! Lane-generic arithmetic, so that a contact law is written once and runs
//! both on one contact (`f64`) and on [`LANES`] contacts at a time ([`F8`]).
//!
//! A law written against [`Real`] uses `select` where scalar code would
//! branch: both sides are computed and each lane keeps its own. Every
//! operation is IEEE-754 and lane-wise (add, sub, mul, div, sqrt; no fused
//! multiply-add, no reassociation), so a lane of [`F8`] holds exactly the bits
//! the same expression gives on `f64`: the batched kernel and the scalar
//! kernel agree bit for bit, and results do not depend on how contacts are
//! grouped into lanes. `F8` is a plain array; where the build targets AVX2
//! (`target-cpu=native` on such a CPU) its operations are AVX2 instructions on
//! two halves of four lanes, elsewhere lane loops. Both are the same IEEE-754
//! operations, so both give the same bits.

use std::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};

/// Contacts per batch of the batched kernel.
pub const LANES: usize = 8;

/// Lane mask: `bool` for one contact, [`M8`] for a batch.
pub trait Mask: Copy {
    /// Both.
    fn and(self, o: Self) -> Self;
    /// Whether any lane is set.
    fn any(self) -> bool;
}

/// A float or a batch of floats.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
{
    /// Lane mask.
    type Mask: Mask;
    /// Every lane `v`.
    fn splat(v: f64) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// `self > o`.
    fn gt(self, o: Self) -> Self::Mask;
    /// `self < o`.
    fn lt(self, o: Self) -> Self::Mask;
    /// `self != o`.
    fn ne(self, o: Self) -> Self::Mask;
    /// `self == o`.
    fn equal(self, o: Self) -> Self::Mask;
    /// Lanes that are infinite.
    fn is_inf(self) -> Self::Mask;
    /// `a` where `m`, else `b`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// `self^e` (the scalar library power, lane by lane).
    fn powf(self, e: f64) -> Self;
}

impl Mask for bool {
    #[inline(always)]
    fn and(self, o: bool) -> bool {
        self & o
    }
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
}

impl Real for f64 {
    type Mask = bool;
    #[inline(always)]
    fn splat(v: f64) -> f64 {
        v
    }
    #[inline(always)]
    fn sqrt(self) -> f64 {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> f64 {
        f64::abs(self)
    }
    #[inline(always)]
    fn gt(self, o: f64) -> bool {
        self > o
    }
    #[inline(always)]
    fn lt(self, o: f64) -> bool {
        self < o
    }
    #[inline(always)]
    fn ne(self, o: f64) -> bool {
        self != o
    }
    #[inline(always)]
    fn equal(self, o: f64) -> bool {
        self == o
    }
    #[inline(always)]
    fn is_inf(self) -> bool {
        self.is_infinite()
    }
    #[inline(always)]
    fn select(m: bool, a: f64, b: f64) -> f64 {
        if m {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn powf(self, e: f64) -> f64 {
        f64::powf(self, e)
    }
}

/// [`LANES`] floats.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct F8(pub [f64; LANES]);

/// [`LANES`] flags: with AVX2 two compare results of four lanes (a lane
/// all ones where set), else one `bool` per lane.
#[derive(Clone, Copy, Debug)]
pub struct M8(MaskLanes);

#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
type MaskLanes = [core::arch::x86_64::__m256d; 2];
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
type MaskLanes = [bool; LANES];

impl Mask for M8 {
    #[inline(always)]
    fn and(self, o: M8) -> M8 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return wide::and(self, o);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        return M8(std::array::from_fn(|l| self.0[l] & o.0[l]));
    }
    #[inline(always)]
    fn any(self) -> bool {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return wide::any(self);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        return self.0.iter().fold(false, |a, &b| a | b);
    }
}

impl M8 {
    /// The lanes as bits, lane `l` at bit `l`.
    #[inline(always)]
    pub fn bits(self) -> u32 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return wide::bits(self);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        return self.0.iter().enumerate().fold(0, |b, (l, &m)| b | (m as u32) << l);
    }
}

impl F8 {
    /// `self >= o` per lane (false where either is NaN, as Rust's `>=`).
    #[inline(always)]
    pub fn ge(self, o: F8) -> M8 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return wide::ge(self, o);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        return cmp(self.0, o.0, |a, b| a >= b);
    }
}

/// `F8` as two AVX2 registers. Left to vectorise the lane loops of the
/// portable form, the compiler split a batch's arithmetic into pieces of
/// one, two and four lanes and spilled between them: the laws of deck (a)
/// took 17.3 ns per contact in `examples/law_floor.rs`, 6.9 ns here (one
/// AVX-512 register: 8.7 ns, its square roots and divisions are no faster
/// per lane and it lowers the clock). Each operation is the IEEE-754 one
/// the portable form applies lane by lane (correctly rounded add, sub, mul,
/// div, sqrt; sign-bit negation and absolute value; ordered compares as
/// Rust's `<`, `>`, `==`, unordered `!=`), so both give the same bits.
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
mod wide {
    use super::{F8, M8};
    use core::arch::x86_64::*;

    /// The two halves of `F8`, four lanes each.
    type H = [__m256d; 2];

    #[inline(always)]
    pub(super) fn r(a: F8) -> H {
        // SAFETY: F8 is eight f64 in 64 bytes, as two __m256d
        unsafe { core::mem::transmute::<F8, H>(a) }
    }
    #[inline(always)]
    pub(super) fn f(a: H) -> F8 {
        // SAFETY: as in `r`, the other way
        unsafe { core::mem::transmute::<H, F8>(a) }
    }
    /// Apply a four-lane operation to both halves.
    macro_rules! halves {
        ($name:ident, $op:ident) => {
            #[inline(always)]
            pub(super) fn $name(a: F8, b: F8) -> F8 {
                let (a, b) = (r(a), r(b));
                // SAFETY: compiled only where the build enables AVX2
                // (target-cpu=native on such a CPU), so the CPU has it
                unsafe { f([$op(a[0], b[0]), $op(a[1], b[1])]) }
            }
        };
    }
    halves!(add, _mm256_add_pd);
    halves!(sub, _mm256_sub_pd);
    halves!(mul, _mm256_mul_pd);
    halves!(div, _mm256_div_pd);
    halves!(xor, _mm256_xor_pd);
    halves!(andnot, _mm256_andnot_pd);
    #[inline(always)]
    pub(super) fn splat(v: f64) -> F8 {
        // SAFETY: as in `halves`
        unsafe { f([_mm256_set1_pd(v); 2]) }
    }
    #[inline(always)]
    pub(super) fn neg(a: F8) -> F8 {
        xor(a, splat(-0.0))
    }
    #[inline(always)]
    pub(super) fn abs(a: F8) -> F8 {
        andnot(splat(-0.0), a)
    }
    #[inline(always)]
    pub(super) fn sqrt(a: F8) -> F8 {
        let a = r(a);
        // SAFETY: as in `halves`
        unsafe { f([_mm256_sqrt_pd(a[0]), _mm256_sqrt_pd(a[1])]) }
    }
    macro_rules! compare {
        ($name:ident, $pred:ident) => {
            #[inline(always)]
            pub(super) fn $name(a: F8, b: F8) -> M8 {
                let (a, b) = (r(a), r(b));
                // SAFETY: as in `halves`
                unsafe { M8([_mm256_cmp_pd::<$pred>(a[0], b[0]), _mm256_cmp_pd::<$pred>(a[1], b[1])]) }
            }
        };
    }
    compare!(gt, _CMP_GT_OQ);
    compare!(lt, _CMP_LT_OQ);
    compare!(ne, _CMP_NEQ_UQ);
    compare!(equal, _CMP_EQ_OQ);
    compare!(ge, _CMP_GE_OQ);
    #[inline(always)]
    pub(super) fn and(a: M8, b: M8) -> M8 {
        // SAFETY: as in `halves`
        unsafe { M8([_mm256_and_pd(a.0[0], b.0[0]), _mm256_and_pd(a.0[1], b.0[1])]) }
    }
    #[inline(always)]
    pub(super) fn any(m: M8) -> bool {
        // SAFETY: as in `halves`
        unsafe { (_mm256_movemask_pd(m.0[0]) | _mm256_movemask_pd(m.0[1])) != 0 }
    }
    #[inline(always)]
    pub(super) fn bits(m: M8) -> u32 {
        // SAFETY: as in `halves`
        unsafe { (_mm256_movemask_pd(m.0[0]) | _mm256_movemask_pd(m.0[1]) << 4) as u32 }
    }
    /// x, y, z of `v`, and a zero.
    #[inline(always)]
    fn row(v: &[f64; 3]) -> __m256d {
        let p = v.as_ptr();
        // SAFETY (both forms): `p` is three f64 in a row, and the masked-off
        // fourth lane is neither read nor can it fault; as in `halves` for
        // the instructions
        #[cfg(target_feature = "avx512vl")]
        return unsafe { _mm256_maskz_loadu_pd(0b0111, p) };
        #[cfg(not(target_feature = "avx512vl"))]
        unsafe {
            _mm256_insertf128_pd::<1>(_mm256_castpd128_pd256(_mm_loadu_pd(p)), _mm_load_sd(p.add(2)))
        }
    }
    /// Four rows of x, y, z (and a lane not read) as x, y and z of four lanes.
    #[inline(always)]
    fn columns(r: [__m256d; 4]) -> [__m256d; 3] {
        // SAFETY: as in `halves`
        unsafe {
            let xz01 = _mm256_unpacklo_pd(r[0], r[1]);
            let y01 = _mm256_unpackhi_pd(r[0], r[1]);
            let xz23 = _mm256_unpacklo_pd(r[2], r[3]);
            let y23 = _mm256_unpackhi_pd(r[2], r[3]);
            [_mm256_permute2f128_pd::<0x20>(xz01, xz23), _mm256_permute2f128_pd::<0x20>(y01, y23), _mm256_permute2f128_pd::<0x31>(xz01, xz23)]
        }
    }
    /// See `Vec3::rows`.
    #[inline(always)]
    pub(super) fn rows(rows: [&[f64; 3]; 8], plus: Option<[&[f64; 3]; 8]>) -> super::Vec3<F8> {
        let reg = |l: usize| match plus {
            // SAFETY: as in `halves`
            Some(p) => unsafe { _mm256_add_pd(row(rows[l]), row(p[l])) },
            None => row(rows[l]),
        };
        let lo = columns([reg(0), reg(1), reg(2), reg(3)]);
        let hi = columns([reg(4), reg(5), reg(6), reg(7)]);
        super::Vec3 { x: f([lo[0], hi[0]]), y: f([lo[1], hi[1]]), z: f([lo[2], hi[2]]) }
    }
    #[inline(always)]
    pub(super) fn select(m: M8, a: F8, b: F8) -> F8 {
        let (a, b) = (r(a), r(b));
        // SAFETY: as in `halves`; the blend takes its second operand where
        // the mask lane is all ones
        unsafe { f([_mm256_blendv_pd(b[0], a[0], m.0[0]), _mm256_blendv_pd(b[1], a[1], m.0[1])]) }
    }
}

#[inline(always)]
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
fn map2(a: [f64; LANES], b: [f64; LANES], f: impl Fn(f64, f64) -> f64) -> [f64; LANES] {
    let mut r = [0.0; LANES];
    for l in 0..LANES {
        r[l] = f(a[l], b[l]);
    }
    r
}

#[inline(always)]
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
fn cmp(a: [f64; LANES], b: [f64; LANES], f: impl Fn(f64, f64) -> bool) -> M8 {
    let mut r = [false; LANES];
    for l in 0..LANES {
        r[l] = f(a[l], b[l]);
    }
    M8(r)
}

macro_rules! f8_op {
    ($tr:ident, $f:ident, $atr:ident, $af:ident, $op:tt) => {
        impl $tr for F8 {
            type Output = F8;
            #[inline(always)]
            fn $f(self, o: F8) -> F8 {
                #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
                return wide::$f(self, o);
                #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
                return F8(map2(self.0, o.0, |a, b| a $op b));
            }
        }
        impl $tr<f64> for F8 {
            type Output = F8;
            #[inline(always)]
            fn $f(self, o: f64) -> F8 {
                self $op F8::splat(o)
            }
        }
        impl $atr for F8 {
            #[inline(always)]
            fn $af(&mut self, o: F8) {
                *self = *self $op o;
            }
        }
    };
}
f8_op!(Add, add, AddAssign, add_assign, +);
f8_op!(Sub, sub, SubAssign, sub_assign, -);
f8_op!(Mul, mul, MulAssign, mul_assign, *);
f8_op!(Div, div, DivAssign, div_assign, /);

impl Neg for F8 {
    type Output = F8;
    #[inline(always)]
    fn neg(self) -> F8 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return wide::neg(self);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        return F8(self.0.map(|v| -v));
    }
}

impl Real for F8 {
    type Mask = M8;
    #[inline(always)]
    fn splat(v: f64) -> F8 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return wide::splat(v);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        return F8([v; LANES]);
    }
    #[inline(always)]
    fn sqrt(self) -> F8 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return wide::sqrt(self);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        return F8(self.0.map(f64::sqrt));
    }
    #[inline(always)]
    fn abs(self) -> F8 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return wide::abs(self);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        return F8(self.0.map(f64::abs));
    }
    #[inline(always)]
    fn gt(self, o: F8) -> M8 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return wide::gt(self, o);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        return cmp(self.0, o.0, |a, b| a > b);
    }
    #[inline(always)]
    fn lt(self, o: F8) -> M8 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return wide::lt(self, o);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        return cmp(self.0, o.0, |a, b| a < b);
    }
    #[inline(always)]
    fn ne(self, o: F8) -> M8 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return wide::ne(self, o);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        return cmp(self.0, o.0, |a, b| a != b);
    }
    #[inline(always)]
    fn equal(self, o: F8) -> M8 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return wide::equal(self, o);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        return cmp(self.0, o.0, |a, b| a == b);
    }
    #[inline(always)]
    fn is_inf(self) -> M8 {
        self.abs().equal(F8::splat(f64::INFINITY))
    }
    #[inline(always)]
    fn select(m: M8, a: F8, b: F8) -> F8 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return wide::select(m, a, b);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        return F8(std::array::from_fn(|l| if m.0[l] { a.0[l] } else { b.0[l] }));
    }
    #[inline(always)]
    fn powf(self, e: f64) -> F8 {
        F8(self.0.map(|v| v.powf(e)))
    }
}

/// A 3-vector of lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vec3<R> {
    /// x.
    pub x: R,
    /// y.
    pub y: R,
    /// z.
    pub z: R,
}

impl<R: Real> Vec3<R> {
    /// From components.
    #[inline(always)]
    pub fn new(x: R, y: R, z: R) -> Self {
        Vec3 { x, y, z }
    }
    /// Zero.
    #[inline(always)]
    pub fn zeros() -> Self {
        let z = R::splat(0.0);
        Vec3 { x: z, y: z, z }
    }
    /// Dot product, summed x + y + z in that order (as nalgebra).
    #[inline(always)]
    pub fn dot(&self, o: &Self) -> R {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    /// Cross product (as nalgebra: each component a difference of products).
    #[inline(always)]
    pub fn cross(&self, o: &Self) -> Self {
        Vec3 { x: self.y * o.z - self.z * o.y, y: self.z * o.x - self.x * o.z, z: self.x * o.y - self.y * o.x }
    }
    /// Squared length.
    #[inline(always)]
    pub fn norm_squared(&self) -> R {
        self.dot(self)
    }
    /// Length.
    #[inline(always)]
    pub fn norm(&self) -> R {
        self.norm_squared().sqrt()
    }
    /// `a` where `m`, else `b`, per lane.
    #[inline(always)]
    pub fn select(m: R::Mask, a: Self, b: Self) -> Self {
        Vec3 { x: R::select(m, a.x, b.x), y: R::select(m, a.y, b.y), z: R::select(m, a.z, b.z) }
    }
}

impl<R: Real> Add for Vec3<R> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Vec3 { x: self.x + o.x, y: self.y + o.y, z: self.z + o.z }
    }
}
impl<R: Real> Sub for Vec3<R> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Vec3 { x: self.x - o.x, y: self.y - o.y, z: self.z - o.z }
    }
}
impl<R: Real> Neg for Vec3<R> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Vec3 { x: -self.x, y: -self.y, z: -self.z }
    }
}
impl<R: Real> Mul<R> for Vec3<R> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: R) -> Self {
        Vec3 { x: self.x * s, y: self.y * s, z: self.z * s }
    }
}
impl<R: Real> Div<R> for Vec3<R> {
    type Output = Self;
    #[inline(always)]
    fn div(self, s: R) -> Self {
        Vec3 { x: self.x / s, y: self.y / s, z: self.z / s }
    }
}
impl<R: Real> AddAssign for Vec3<R> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
impl<R: Real> SubAssign for Vec3<R> {
    #[inline(always)]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}

impl From<super::V3> for Vec3<f64> {
    #[inline(always)]
    fn from(v: super::V3) -> Self {
        Vec3 { x: v.x, y: v.y, z: v.z }
    }
}
impl From<Vec3<f64>> for super::V3 {
    #[inline(always)]
    fn from(v: Vec3<f64>) -> Self {
        super::V3::new(v.x, v.y, v.z)
    }
}

impl Vec3<F8> {
    /// Lane `l` as a vector.
    #[inline(always)]
    pub fn lane(&self, l: usize) -> super::V3 {
        super::V3::new(self.x.0[l], self.y.0[l], self.z.0[l])
    }
    /// Lane `l` from `rows[l]`: eight vectors turned into lanes. With AVX2,
    /// each row is one register (one masked load with AVX-512VL) and four
    /// rows become three registers of lanes by seven shuffles, where lane by
    /// lane it took a load and a store for each value and then a wide load
    /// of what the narrow stores wrote (which waits for those stores).
    #[inline(always)]
    pub fn rows(rows: [&super::V3; LANES]) -> Vec3<F8> {
        Vec3::rows_of(rows.map(|v| &v.data.0[0]))
    }
    /// [`Vec3::rows`] of three values in a row each (a pair's history).
    #[inline(always)]
    pub fn rows_of(rows: [&[f64; 3]; LANES]) -> Vec3<F8> {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return wide::rows(rows, None);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        return Vec3 { x: F8(rows.map(|v| v[0])), y: F8(rows.map(|v| v[1])), z: F8(rows.map(|v| v[2])) };
    }
    /// Lane `l` from `rows[l] + plus[l]` (added as nalgebra adds, component
    /// by component).
    #[inline(always)]
    pub fn rows_plus(rows: [&super::V3; LANES], plus: [&super::V3; LANES]) -> Vec3<F8> {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return wide::rows(rows.map(|v| &v.data.0[0]), Some(plus.map(|v| &v.data.0[0])));
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        {
            let sum: [super::V3; LANES] = std::array::from_fn(|l| rows[l] + plus[l]);
            return Vec3::rows(sum.each_ref());
        }
    }
}

/// Pair coefficients as lanes: one `PairParams` for one contact, or one per
/// lane of a batch (broadcast when the batch shares one type pair).
pub trait Coeffs<R> {
    /// Field `f` of each lane's coefficients.
    fn get(&self, f: impl Fn(&super::PairParams) -> f64) -> R;
}

impl Coeffs<f64> for super::PairParams {
    #[inline(always)]
    fn get(&self, f: impl Fn(&super::PairParams) -> f64) -> f64 {
        f(self)
    }
}

/// The coefficients of a batch: each lane's, and whether they are all one.
pub struct BatchCoeffs<'a> {
    /// Per lane.
    pub p: [&'a super::PairParams; LANES],
    /// All lanes share `p[0]`.
    pub uniform: bool,
}

impl Coeffs<F8> for BatchCoeffs<'_> {
    #[inline(always)]
    fn get(&self, f: impl Fn(&super::PairParams) -> f64) -> F8 {
        if self.uniform {
            F8::splat(f(self.p[0]))
        } else {
            let mut r = [0.0; LANES];
            for l in 0..LANES {
                r[l] = f(self.p[l]);
            }
            F8(r)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Awkward values: signed zeros, infinities, NaN, subnormals, values
    /// whose quotients and roots round.
    const VALUES: [f64; 16] =
        [0.0, -0.0, 1.0, -1.0, 3.0, 0.1, -7.5e-300, 5e-324, f64::INFINITY, f64::NEG_INFINITY, f64::NAN, 2.0, 1e308, -1e-3, 1.0 / 3.0, 9.0];

    /// Every lane of `a op b` on `F8` has the bits of the same `f64`
    /// operation, for every pair of awkward values: the AVX2 form and the
    /// lane loops agree.
    #[test]
    fn each_lane_has_the_bits_of_the_scalar_operation() {
        let bits = |v: f64| if v.is_nan() { u64::MAX } else { v.to_bits() };
        let mut checked = 0;
        for (s, &x) in VALUES.iter().enumerate() {
            // lane l pairs x with VALUES[(s + l) % 16] and the next 8 along
            for shift in [0, 8] {
                let ys: [f64; LANES] = std::array::from_fn(|l| VALUES[(s + l + shift) % VALUES.len()]);
                let (a, b) = (F8::splat(x), F8(ys));
                let ops: [(&str, F8, fn(f64, f64) -> f64); 8] = [
                    ("add", a + b, |x, y| x + y),
                    ("sub", a - b, |x, y| x - y),
                    ("mul", a * b, |x, y| x * y),
                    ("div", a / b, |x, y| x / y),
                    ("neg", -b, |_, y| -y),
                    ("abs", b.abs(), |_, y| y.abs()),
                    ("sqrt", b.sqrt(), |_, y| y.sqrt()),
                    ("select", F8::select(a.lt(b), a, b), |x, y| if x < y { x } else { y }),
                ];
                for (name, got, want) in ops {
                    for l in 0..LANES {
                        assert_eq!(bits(got.0[l]), bits(want(x, ys[l])), "{name}({x:e}, {:e}) lane {l}", ys[l]);
                        checked += 1;
                    }
                }
                let masks: [(&str, M8, fn(f64, f64) -> bool); 6] = [
                    ("gt", a.gt(b), |x, y| x > y),
                    ("ge", a.ge(b), |x, y| x >= y),
                    ("lt", a.lt(b), |x, y| x < y),
                    ("ne", a.ne(b), |x, y| x != y),
                    ("equal", a.equal(b), |x, y| x == y),
                    ("is_inf", b.is_inf(), |_, y| y.is_infinite()),
                ];
                for (name, m, want) in masks {
                    let picked = F8::select(m, F8::splat(1.0), F8::splat(0.0));
                    for l in 0..LANES {
                        assert_eq!(picked.0[l] == 1.0, want(x, ys[l]), "{name}({x:e}, {:e}) lane {l}", ys[l]);
                    }
                    assert_eq!(m.any(), (0..LANES).any(|l| want(x, ys[l])), "{name} any");
                    assert_eq!(m.bits(), (0..LANES).fold(0, |b, l| b | (want(x, ys[l]) as u32) << l), "{name} bits");
                    assert_eq!(m.and(b.gt(F8::splat(0.0))).any(), (0..LANES).any(|l| want(x, ys[l]) && ys[l] > 0.0), "{name} and");
                }
            }
        }
        assert_eq!(checked, 16 * 2 * 8 * LANES);
    }

    /// `Vec3::rows` puts row l in lane l, and `rows_plus` the sum of two
    /// rows with the bits of nalgebra's sum; the rows lie anywhere in a
    /// slice, the last one at its very end (no read beyond a row).
    #[test]
    fn rows_become_lanes() {
        use crate::physics::V3;
        let v: Vec<V3> = (0..24).map(|k| V3::new(VALUES[k % 16], VALUES[(k + 5) % 16], 0.1 * k as f64 - 1.0)).collect();
        let bits = |v: f64| if v.is_nan() { u64::MAX } else { v.to_bits() };
        let picks = [[23, 0, 7, 7, 1, 12, 22, 3], [5, 9, 2, 17, 23, 11, 0, 8]];
        for idx in picks {
            for other in picks {
                let rows = Vec3::rows(idx.map(|k| &v[k]));
                let sums = Vec3::rows_plus(idx.map(|k| &v[k]), other.map(|k| &v[k]));
                for l in 0..LANES {
                    let (want, sum) = (v[idx[l]], v[idx[l]] + v[other[l]]);
                    let got = [rows.x.0[l], rows.y.0[l], rows.z.0[l]].map(bits);
                    assert_eq!(got, [want.x, want.y, want.z].map(bits), "rows, lane {l}");
                    let got = [sums.x.0[l], sums.y.0[l], sums.z.0[l]].map(bits);
                    assert_eq!(got, [sum.x, sum.y, sum.z].map(bits), "rows_plus, lane {l}");
                }
            }
        }
    }
}
