//! Lane-generic arithmetic, so that a contact law is written once and runs
//! both on one contact (`f64`) and on [`LANES`] contacts at a time ([`F8`]).
//!
//! A law written against [`Real`] uses `select` where scalar code would
//! branch: both sides are computed and each lane keeps its own. Every
//! operation is IEEE-754 and lane-wise (add, sub, mul, div, sqrt; no fused
//! multiply-add, no reassociation), so a lane of [`F8`] holds exactly the bits
//! the same expression gives on `f64`: the batched kernel and the scalar
//! kernel agree bit for bit, and results do not depend on how contacts are
//! grouped into lanes. `F8` is a plain array the compiler turns into vector
//! instructions (AVX2/AVX-512 with `target-cpu=native`); no intrinsics, so it
//! builds and gives the same bits on any CPU.

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

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

/// [`LANES`] flags.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct M8(pub [bool; LANES]);

#[inline(always)]
fn map2(a: [f64; LANES], b: [f64; LANES], f: impl Fn(f64, f64) -> f64) -> [f64; LANES] {
    let mut r = [0.0; LANES];
    for l in 0..LANES {
        r[l] = f(a[l], b[l]);
    }
    r
}

#[inline(always)]
fn cmp(a: [f64; LANES], b: [f64; LANES], f: impl Fn(f64, f64) -> bool) -> M8 {
    let mut r = [false; LANES];
    for l in 0..LANES {
        r[l] = f(a[l], b[l]);
    }
    M8(r)
}

impl Mask for M8 {
    #[inline(always)]
    fn and(self, o: M8) -> M8 {
        let mut r = self.0;
        for l in 0..LANES {
            r[l] &= o.0[l];
        }
        M8(r)
    }
    #[inline(always)]
    fn any(self) -> bool {
        self.0.iter().fold(false, |a, &b| a | b)
    }
}

macro_rules! f8_op {
    ($tr:ident, $f:ident, $atr:ident, $af:ident, $op:tt) => {
        impl $tr for F8 {
            type Output = F8;
            #[inline(always)]
            fn $f(self, o: F8) -> F8 {
                F8(map2(self.0, o.0, |a, b| a $op b))
            }
        }
        impl $tr<f64> for F8 {
            type Output = F8;
            #[inline(always)]
            fn $f(self, o: f64) -> F8 {
                F8(map2(self.0, [o; LANES], |a, b| a $op b))
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

impl Div for F8 {
    type Output = F8;
    #[inline(always)]
    fn div(self, o: F8) -> F8 {
        F8(map2(self.0, o.0, |a, b| a / b))
    }
}
impl Div<f64> for F8 {
    type Output = F8;
    #[inline(always)]
    fn div(self, o: f64) -> F8 {
        F8(map2(self.0, [o; LANES], |a, b| a / b))
    }
}
impl Neg for F8 {
    type Output = F8;
    #[inline(always)]
    fn neg(self) -> F8 {
        let mut r = self.0;
        for v in &mut r {
            *v = -*v;
        }
        F8(r)
    }
}

impl Real for F8 {
    type Mask = M8;
    #[inline(always)]
    fn splat(v: f64) -> F8 {
        F8([v; LANES])
    }
    #[inline(always)]
    fn sqrt(self) -> F8 {
        let mut r = self.0;
        for v in &mut r {
            *v = v.sqrt();
        }
        F8(r)
    }
    #[inline(always)]
    fn abs(self) -> F8 {
        let mut r = self.0;
        for v in &mut r {
            *v = v.abs();
        }
        F8(r)
    }
    #[inline(always)]
    fn gt(self, o: F8) -> M8 {
        cmp(self.0, o.0, |a, b| a > b)
    }
    #[inline(always)]
    fn lt(self, o: F8) -> M8 {
        cmp(self.0, o.0, |a, b| a < b)
    }
    #[inline(always)]
    fn ne(self, o: F8) -> M8 {
        cmp(self.0, o.0, |a, b| a != b)
    }
    #[inline(always)]
    fn equal(self, o: F8) -> M8 {
        cmp(self.0, o.0, |a, b| a == b)
    }
    #[inline(always)]
    fn is_inf(self) -> M8 {
        cmp(self.0, self.0, |a, _| a.is_infinite())
    }
    #[inline(always)]
    fn select(m: M8, a: F8, b: F8) -> F8 {
        let mut r = b.0;
        for l in 0..LANES {
            if m.0[l] {
                r[l] = a.0[l];
            }
        }
        F8(r)
    }
    #[inline(always)]
    fn powf(self, e: f64) -> F8 {
        let mut r = self.0;
        for v in &mut r {
            *v = v.powf(e);
        }
        F8(r)
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
