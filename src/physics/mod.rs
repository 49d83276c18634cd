//! Pure contact laws, one file per deck keyword, grouped by model axis like
//! LIGGGHTS `pair_style gran`: `normal/`, `tangential/`, `cohesion/`,
//! `rolling/`. Laws read a read-only [`Contact`] and the pair's
//! [`PairParams`], own a slice of per-contact history, and add their part to a
//! [`ContactOut`]. The order is written down once, in
//! [`crate::engine::kernel`]: normal -> cohesion -> tangential -> rolling.
//!
//! Sign conventions (as LAMMPS `pair_gran_*`): `n` points from j to i,
//! `delta > 0` is overlap, `vn = (v_i - v_j) . n` is negative while the
//! spheres approach, `fn_total > 0` pushes i away from j. The force on i is
//! `fn_total * n + ft`; j gets the opposite force.
//!
//! Units: SI inside (or whatever consistent set the deck's `units` gives; the
//! laws are unit-agnostic).

pub mod cohesion;
pub mod lanes;
pub mod mixing;
pub mod normal;
pub mod rolling;
pub mod tangential;

use lanes::{Coeffs, Real, Vec3};

use nalgebra::Vector3;

/// 3-vector of f64.
pub type V3 = Vector3<f64>;

/// Geometry and kinematics of one contact at one step (pair or particle-wall).
#[derive(Clone, Copy, Debug)]
pub struct Contact {
    /// Unit normal from j (or the wall) to i.
    pub n: V3,
    /// Centre distance (wall: distance from centre to the wall's contact point).
    pub r: f64,
    /// Overlap `ri + rj - r` (> 0 in contact; < 0 apart, for non-contact cohesion).
    pub delta: f64,
    /// Radius of i.
    pub ri: f64,
    /// Radius of j (`f64::INFINITY` for walls).
    pub rj: f64,
    /// Effective radius R* = ri rj / (ri + rj) (walls: ri).
    pub r_eff: f64,
    /// Mass of i.
    pub mi: f64,
    /// Mass of j (`f64::INFINITY` for walls and frozen particles).
    pub mj: f64,
    /// Effective mass m* (walls, frozen partners: the mobile particle's mass).
    pub m_eff: f64,
    /// Relative centre velocity v_i - v_j (walls: v_i - v_wall at the contact point).
    pub vr: V3,
    /// Normal relative speed `vr . n` (negative approaching).
    pub vn: f64,
    /// Angular velocity of i.
    pub wi: V3,
    /// Angular velocity of j (zero for static walls).
    pub wj: V3,
    /// Time step.
    pub dt: f64,
}

impl Contact {
    /// A contact of sphere i (radius `ri`, mass `mi`, spin `wi`) with a wall
    /// of infinite radius and mass: normal `n` from the wall into the
    /// sphere, overlap `delta`, centre-to-contact-point distance `r`,
    /// effective radius `r_eff` (`ri`, or with a curved wall's radius), and
    /// `vr` the sphere's velocity less the wall's at the contact point.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub fn with_wall(n: V3, r: f64, delta: f64, ri: f64, r_eff: f64, mi: f64, vr: V3, wi: V3, dt: f64) -> Contact {
        Contact { n, r, delta, ri, rj: f64::INFINITY, r_eff, mi, mj: f64::INFINITY, m_eff: mi, vr, vn: vr.dot(&n), wi, wj: V3::zeros(), dt }
    }
    /// Whether the surfaces touch.
    #[inline(always)]
    pub fn touching(&self) -> bool {
        self.delta > 0.0
    }
    /// Wall contact (j has infinite radius).
    #[inline(always)]
    pub fn is_wall(&self) -> bool {
        self.rj.is_infinite()
    }
}

/// What the laws of one contact produce, filled in order
/// normal -> cohesion -> tangential -> rolling.
#[derive(Clone, Copy, Debug, Default)]
pub struct ContactOut {
    /// Elastic normal force magnitude (along n, > 0 repulsive).
    pub fn_elastic: f64,
    /// Damping normal force (along n).
    pub fn_damp: f64,
    /// Cohesive normal force (along n, < 0 attractive).
    pub fn_coh: f64,
    /// Normal force the friction cap uses (law-dependent: LIGGGHTS uses the
    /// contact force without cohesion; LAMMPS JKR/DMT use Fne + 2 F_pulloff).
    pub fn_for_friction: f64,
    /// Current normal stiffness (dF/d delta for Hooke; the law's k_n for Hertz),
    /// for rolling models that scale with it.
    pub kn: f64,
    /// Current tangential stiffness.
    pub kt: f64,
    /// Contact radius `a` where the law defines one (Hertz: sqrt(R* delta)).
    pub a: f64,
    /// Normal damping coefficient in force the normal law applied
    /// (`fn_damp = -gamma_n * vn`); LAMMPS `granular` scales its tangential
    /// damping with it (`damp_normal_prefactor`).
    pub gamma_n: f64,
    /// Absolute tangential damping coefficient set by the normal law
    /// (LIGGGHTS `sidata.gammat`; LAMMPS gran/*: m* gamma_t, times the
    /// Hertz factor); force per unit sliding velocity.
    pub gamma_t: f64,
    /// Tangential force on i.
    pub ft: V3,
    /// Torque on i.
    pub torque_i: V3,
    /// Torque on j.
    pub torque_j: V3,
}

impl ContactOut {
    /// Total normal force magnitude along n.
    #[inline(always)]
    pub fn fn_total(&self) -> f64 {
        self.fn_elastic + self.fn_damp + self.fn_coh
    }
    /// Total force on i.
    #[inline(always)]
    pub fn force_i(&self, c: &Contact) -> V3 {
        c.n * self.fn_total() + self.ft
    }
}

/// Coefficients of one type pair (or particle type and wall type), filled at
/// scene build from `fix property/global`, `pair_coeff` or `pair_style`
/// arguments. A law reads only the fields it needs; the rest stay zero.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct PairParams {
    /// Effective Young's modulus Y* (LIGGGHTS mixing, or LAMMPS E_eff).
    pub y_eff: f64,
    /// Effective shear modulus G*.
    pub g_eff: f64,
    /// Coefficient of restitution (LIGGGHTS `coefficientRestitution`).
    pub restitution: f64,
    /// beta = ln e / sqrt(ln^2 e + pi^2) (LIGGGHTS damping), < 0.
    pub beta: f64,
    /// Sliding friction coefficient mu.
    pub mu: f64,
    /// Rolling friction coefficient mu_r.
    pub mu_r: f64,
    /// Rolling viscous damping coefficient (epsd, epsd3).
    pub eta_r: f64,
    /// Rolling stiffness coefficient (epsd3 `rollingStiffness`, 2.25 for epsd).
    pub k_r_coeff: f64,
    /// Cohesion energy density (sjkr, sjkr2), J/m^3; or surface energy gamma
    /// (vdw, dmt, jkr), J/m^2.
    pub cohesion: f64,
    /// Characteristic velocity (LIGGGHTS hooke).
    pub char_vel: f64,
    /// Normal stiffness constant (Hooke kn, LAMMPS Kn, LIGGGHTS `kn`).
    pub kn: f64,
    /// Tangential stiffness constant.
    pub kt: f64,
    /// Normal damping constant (meaning depends on the law).
    pub gamma_n: f64,
    /// Tangential damping constant.
    pub gamma_t: f64,
    /// Whether tangential damping is on (LIGGGHTS `tangential_damping`,
    /// LAMMPS `dampflag`): 1.0 or 0.0.
    pub tangential_damping: f64,
    /// Rolling stiffness (LAMMPS rolling sds k_roll).
    pub k_roll: f64,
    /// Rolling damping (LAMMPS rolling sds gamma_roll).
    pub gamma_roll: f64,
    /// Twisting stiffness, damping and friction (LAMMPS twisting sds).
    pub k_twist: f64,
    /// Twisting damping.
    pub gamma_twist: f64,
    /// Twisting friction coefficient.
    pub mu_twist: f64,
    /// Van der Waals: Hamaker constant A_H.
    pub hamaker: f64,
    /// Van der Waals: minimum separation D_min.
    pub d_min: f64,
    /// Van der Waals: cut-off separation D_max.
    pub d_max: f64,
    /// Viscoelastic dissipative constant A_n (paper Eq. 10).
    pub a_n: f64,
    /// Poisson ratio of the pair (where a law needs it alone).
    pub poisson: f64,
    /// Extra range beyond contact over which the pair interacts (vdW D_max,
    /// JKR pull-off distance); the neighbour cut-off adds it.
    pub extra_range: f64,
    /// Whether `limit_damping` (LAMMPS) / `limitForce` (LIGGGHTS) is on: 1.0 or 0.0.
    pub limit_damping: f64,
}

/// A normal force law.
pub trait NormalLaw: Sync {
    /// History values this law keeps per contact.
    const HISTORY: usize;
    /// The factor each history value takes when the pair's two particles
    /// swap roles (i becomes j): -1.0 for a vector that points from one to
    /// the other (a tangential displacement, a relative rotation), 1.0 for a
    /// value both see alike (a flag, a magnitude). One per history value; the
    /// pair list applies it when a pair's orientation changes across a
    /// rebuild (its first particle is the one of smaller storage index).
    const FLIP: &'static [f64] = &[];
    /// Whether the law acts only when the surfaces touch. Laws that keep a
    /// contact beyond touching (JKR) set it to false and decide in
    /// [`NormalLaw::active`]; the kernel then also hands them pairs that are
    /// apart.
    const CONTACT_ONLY: bool = true;
    /// Whether the contact is on at this overlap, given the law's history
    /// (zeroed whenever the contact was off). Consulted only when
    /// `CONTACT_ONLY` is false; the default is `delta > 0`.
    #[inline(always)]
    fn active(&self, c: &Contact, _p: &PairParams, _hist: &[f64]) -> bool {
        c.delta > 0.0
    }
    /// Fill `fn_elastic`, `fn_damp`, `fn_for_friction`, `kn`, `kt`, `a`.
    fn normal(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut);
    /// Whether the law has a lane form ([`NormalLaw::normal_lanes`]); the
    /// kernel batches contacts only when every law of the scene has one.
    const LANES: bool = false;
    /// [`NormalLaw::normal`] on lanes (one contact or a batch).
    #[inline(always)]
    fn normal_lanes<R: Real, P: Coeffs<R>>(&self, _c: &ContactL<R>, _p: &P, _hist: &mut [R], _out: &mut OutL<R>) {
        unreachable!("law without a lane form")
    }
}

/// A tangential (friction) law. Also applies the torque of the tangential
/// force, with its engine's lever arm convention.
pub trait TangentialLaw: Sync {
    /// History values per contact.
    const HISTORY: usize;
    /// The factor each history value takes when the pair's two particles
    /// swap roles (i becomes j): -1.0 for a vector that points from one to
    /// the other (a tangential displacement, a relative rotation), 1.0 for a
    /// value both see alike (a flag, a magnitude). One per history value; the
    /// pair list applies it when a pair's orientation changes across a
    /// rebuild (its first particle is the one of smaller storage index).
    const FLIP: &'static [f64] = &[];
    /// Fill `ft`, add to `torque_i`, `torque_j`.
    fn tangential(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut);
    /// Whether the law has a lane form.
    const LANES: bool = false;
    /// [`TangentialLaw::tangential`] on lanes.
    #[inline(always)]
    fn tangential_lanes<R: Real, P: Coeffs<R>>(&self, _c: &ContactL<R>, _p: &P, _hist: &mut [R], _out: &mut OutL<R>) {
        unreachable!("law without a lane form")
    }
}

/// A cohesion law (adds to `fn_coh`).
pub trait CohesionLaw: Sync {
    /// History values per contact.
    const HISTORY: usize;
    /// The factor each history value takes when the pair's two particles
    /// swap roles (i becomes j): -1.0 for a vector that points from one to
    /// the other (a tangential displacement, a relative rotation), 1.0 for a
    /// value both see alike (a flag, a magnitude). One per history value; the
    /// pair list applies it when a pair's orientation changes across a
    /// rebuild (its first particle is the one of smaller storage index).
    const FLIP: &'static [f64] = &[];
    /// Whether it acts on pairs that do not touch (vdW): the neighbour list
    /// and the kernel then include them.
    const NONCONTACT: bool;
    /// Add the cohesive normal force.
    fn cohesion(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut);
    /// Whether the law has a lane form.
    const LANES: bool = false;
    /// [`CohesionLaw::cohesion`] on lanes.
    #[inline(always)]
    fn cohesion_lanes<R: Real, P: Coeffs<R>>(&self, _c: &ContactL<R>, _p: &P, _hist: &mut [R], _out: &mut OutL<R>) {
        unreachable!("law without a lane form")
    }
}

/// A rolling (and twisting) resistance law (adds torques).
pub trait RollingLaw: Sync {
    /// History values per contact.
    const HISTORY: usize;
    /// The factor each history value takes when the pair's two particles
    /// swap roles (i becomes j): -1.0 for a vector that points from one to
    /// the other (a tangential displacement, a relative rotation), 1.0 for a
    /// value both see alike (a flag, a magnitude). One per history value; the
    /// pair list applies it when a pair's orientation changes across a
    /// rebuild (its first particle is the one of smaller storage index).
    const FLIP: &'static [f64] = &[];
    /// Add rolling/twisting torques to `torque_i` / `torque_j`.
    fn rolling(&self, c: &Contact, p: &PairParams, hist: &mut [f64], out: &mut ContactOut);
    /// Whether the law has a lane form.
    const LANES: bool = false;
    /// [`RollingLaw::rolling`] on lanes.
    #[inline(always)]
    fn rolling_lanes<R: Real, P: Coeffs<R>>(&self, _c: &ContactL<R>, _p: &P, _hist: &mut [R], _out: &mut OutL<R>) {
        unreachable!("law without a lane form")
    }
}

/// No cohesion: a zero-sized type, compiled away.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoCohesion;
impl CohesionLaw for NoCohesion {
    const HISTORY: usize = 0;
    const NONCONTACT: bool = false;
    #[inline(always)]
    fn cohesion(&self, _: &Contact, _: &PairParams, _: &mut [f64], _: &mut ContactOut) {}
    const LANES: bool = true;
    #[inline(always)]
    fn cohesion_lanes<R: Real, P: Coeffs<R>>(&self, _: &ContactL<R>, _: &P, _: &mut [R], _: &mut OutL<R>) {}
}

/// No rolling resistance: a zero-sized type, compiled away.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoRolling;
impl RollingLaw for NoRolling {
    const HISTORY: usize = 0;
    #[inline(always)]
    fn rolling(&self, _: &Contact, _: &PairParams, _: &mut [f64], _: &mut ContactOut) {}
    const LANES: bool = true;
    #[inline(always)]
    fn rolling_lanes<R: Real, P: Coeffs<R>>(&self, _: &ContactL<R>, _: &P, _: &mut [R], _: &mut OutL<R>) {}
}

/// [`Contact`] on lanes: one contact (`R = f64`) or a batch of pair contacts
/// ([`lanes::F8`]). Same fields and conventions; `wall` is one flag for all
/// lanes (a batch holds pairs, or contacts with walls).
#[derive(Clone, Copy, Debug)]
pub struct ContactL<R> {
    /// Unit normal from j to i.
    pub n: Vec3<R>,
    /// Centre distance.
    pub r: R,
    /// Overlap.
    pub delta: R,
    /// Radius of i.
    pub ri: R,
    /// Radius of j.
    pub rj: R,
    /// Effective radius.
    pub r_eff: R,
    /// Mass of i.
    pub mi: R,
    /// Mass of j.
    pub mj: R,
    /// Effective mass.
    pub m_eff: R,
    /// Relative centre velocity.
    pub vr: Vec3<R>,
    /// Normal relative speed.
    pub vn: R,
    /// Angular velocity of i.
    pub wi: Vec3<R>,
    /// Angular velocity of j.
    pub wj: Vec3<R>,
    /// Time step.
    pub dt: f64,
    /// Whether j is a wall (for every lane).
    pub wall: bool,
}

/// The fields of a contact, moved between [`Contact`] and
/// [`ContactL`]`<f64>` (vectors converted), plus any the target adds.
macro_rules! convert_contact {
    ($c:expr, $to:ident { $($extra:tt)* }) => {
        $to {
            n: $c.n.into(),
            r: $c.r,
            delta: $c.delta,
            ri: $c.ri,
            rj: $c.rj,
            r_eff: $c.r_eff,
            mi: $c.mi,
            mj: $c.mj,
            m_eff: $c.m_eff,
            vr: $c.vr.into(),
            vn: $c.vn,
            wi: $c.wi.into(),
            wj: $c.wj.into(),
            dt: $c.dt,
            $($extra)*
        }
    };
}

impl ContactL<f64> {
    /// One contact's lane form.
    #[inline(always)]
    pub fn one(c: &Contact) -> Self {
        convert_contact!(c, ContactL { wall: c.is_wall() })
    }
}

impl ContactL<lanes::F8> {
    /// Up to [`lanes::LANES`] contacts, one per lane (lanes past `cs.len()`
    /// repeat the last contact), all with the same `wall` flag and time step
    /// (those of `cs[0]`). `cs` must not be empty.
    #[inline(always)]
    pub fn gather(cs: &[Contact]) -> Self {
        use lanes::{F8, LANES};
        let z = F8::splat(0.0);
        let zv = Vec3::zeros();
        let mut l = ContactL {
            n: zv,
            r: z,
            delta: z,
            ri: z,
            rj: z,
            r_eff: z,
            mi: z,
            mj: z,
            m_eff: z,
            vr: zv,
            vn: z,
            wi: zv,
            wj: zv,
            dt: cs[0].dt,
            wall: cs[0].is_wall(),
        };
        let put = |v: &mut Vec3<F8>, k: usize, x: &V3| {
            v.x.0[k] = x.x;
            v.y.0[k] = x.y;
            v.z.0[k] = x.z;
        };
        for k in 0..LANES {
            let c = &cs[k.min(cs.len() - 1)];
            put(&mut l.n, k, &c.n);
            put(&mut l.vr, k, &c.vr);
            put(&mut l.wi, k, &c.wi);
            put(&mut l.wj, k, &c.wj);
            l.r.0[k] = c.r;
            l.delta.0[k] = c.delta;
            l.ri.0[k] = c.ri;
            l.rj.0[k] = c.rj;
            l.r_eff.0[k] = c.r_eff;
            l.mi.0[k] = c.mi;
            l.mj.0[k] = c.mj;
            l.m_eff.0[k] = c.m_eff;
            l.vn.0[k] = c.vn;
        }
        l
    }
}

impl From<ContactL<f64>> for Contact {
    #[inline(always)]
    fn from(c: ContactL<f64>) -> Self {
        convert_contact!(c, Contact {})
    }
}

/// [`ContactOut`] on lanes.
#[derive(Clone, Copy, Debug)]
pub struct OutL<R> {
    /// See [`ContactOut::fn_elastic`].
    pub fn_elastic: R,
    /// See [`ContactOut::fn_damp`].
    pub fn_damp: R,
    /// See [`ContactOut::fn_coh`].
    pub fn_coh: R,
    /// See [`ContactOut::fn_for_friction`].
    pub fn_for_friction: R,
    /// See [`ContactOut::kn`].
    pub kn: R,
    /// See [`ContactOut::kt`].
    pub kt: R,
    /// See [`ContactOut::a`].
    pub a: R,
    /// See [`ContactOut::gamma_n`].
    pub gamma_n: R,
    /// See [`ContactOut::gamma_t`].
    pub gamma_t: R,
    /// Tangential force on i.
    pub ft: Vec3<R>,
    /// Torque on i.
    pub torque_i: Vec3<R>,
    /// Torque on j.
    pub torque_j: Vec3<R>,
}

impl<R: Real> OutL<R> {
    /// All zero (as `ContactOut::default()`).
    #[inline(always)]
    pub fn zeros() -> Self {
        let z = R::splat(0.0);
        let v = Vec3::zeros();
        OutL { fn_elastic: z, fn_damp: z, fn_coh: z, fn_for_friction: z, kn: z, kt: z, a: z, gamma_n: z, gamma_t: z, ft: v, torque_i: v, torque_j: v }
    }
    /// `a` where `m`, else `b`, per lane and field.
    #[inline(always)]
    pub fn select(m: R::Mask, a: &Self, b: &Self) -> Self {
        let s = |x: R, y: R| R::select(m, x, y);
        let v = |x: Vec3<R>, y: Vec3<R>| Vec3::select(m, x, y);
        OutL {
            fn_elastic: s(a.fn_elastic, b.fn_elastic),
            fn_damp: s(a.fn_damp, b.fn_damp),
            fn_coh: s(a.fn_coh, b.fn_coh),
            fn_for_friction: s(a.fn_for_friction, b.fn_for_friction),
            kn: s(a.kn, b.kn),
            kt: s(a.kt, b.kt),
            a: s(a.a, b.a),
            gamma_n: s(a.gamma_n, b.gamma_n),
            gamma_t: s(a.gamma_t, b.gamma_t),
            ft: v(a.ft, b.ft),
            torque_i: v(a.torque_i, b.torque_i),
            torque_j: v(a.torque_j, b.torque_j),
        }
    }
    /// Total normal force along n.
    #[inline(always)]
    pub fn fn_total(&self) -> R {
        self.fn_elastic + self.fn_damp + self.fn_coh
    }
    /// Total force on i.
    #[inline(always)]
    pub fn force_i(&self, c: &ContactL<R>) -> Vec3<R> {
        c.n * self.fn_total() + self.ft
    }
}

/// The fields of a contact's output, moved between [`ContactOut`] and
/// [`OutL`]`<f64>` (vectors converted).
macro_rules! convert_out {
    ($o:expr, $to:ident) => {
        $to {
            fn_elastic: $o.fn_elastic,
            fn_damp: $o.fn_damp,
            fn_coh: $o.fn_coh,
            fn_for_friction: $o.fn_for_friction,
            kn: $o.kn,
            kt: $o.kt,
            a: $o.a,
            gamma_n: $o.gamma_n,
            gamma_t: $o.gamma_t,
            ft: $o.ft.into(),
            torque_i: $o.torque_i.into(),
            torque_j: $o.torque_j.into(),
        }
    };
}

impl OutL<lanes::F8> {
    /// Lane `l` as one contact's output.
    #[inline(always)]
    pub fn lane(&self, l: usize) -> ContactOut {
        ContactOut {
            fn_elastic: self.fn_elastic.0[l],
            fn_damp: self.fn_damp.0[l],
            fn_coh: self.fn_coh.0[l],
            fn_for_friction: self.fn_for_friction.0[l],
            kn: self.kn.0[l],
            kt: self.kt.0[l],
            a: self.a.0[l],
            gamma_n: self.gamma_n.0[l],
            gamma_t: self.gamma_t.0[l],
            ft: self.ft.lane(l),
            torque_i: self.torque_i.lane(l),
            torque_j: self.torque_j.lane(l),
        }
    }
}

impl From<&ContactOut> for OutL<f64> {
    #[inline(always)]
    fn from(o: &ContactOut) -> Self {
        convert_out!(o, OutL)
    }
}

impl From<OutL<f64>> for ContactOut {
    #[inline(always)]
    fn from(o: OutL<f64>) -> Self {
        convert_out!(o, ContactOut)
    }
}

/// Run a lane-form law on one contact: the scalar entry point of a law that
/// is written once on lanes.
#[inline(always)]
pub fn on_one(c: &Contact, out: &mut ContactOut, f: impl FnOnce(&ContactL<f64>, &mut OutL<f64>)) {
    let cl = ContactL::one(c);
    let mut o = OutL::from(&*out);
    f(&cl, &mut o);
    *out = o.into();
}

/// Every law's [`NormalLaw::FLIP`] (and the others') has one factor per
/// history value, each +1 or -1: checked when the crate compiles. The test
/// below keeps the list complete.
macro_rules! check_flip {
    ($($law:ident: $($ty:ty),+;)+) => {
        const _: () = {
            $($(
                let (flip, n) = (<$ty as $law>::FLIP, <$ty as $law>::HISTORY);
                assert!(flip.len() == n, concat!(stringify!($ty), ": FLIP needs one factor per history value"));
                let mut k = 0;
                while k < flip.len() {
                    assert!(flip[k] == 1.0 || flip[k] == -1.0, concat!(stringify!($ty), ": a FLIP factor is +1 or -1"));
                    k += 1;
                }
            )+)+
        };
        /// The laws [`check_flip`] checks, by name.
        #[cfg(test)]
        const CHECKED_LAWS: &[&str] = &[$($(stringify!($ty)),+),+];
    };
}

check_flip! {
    NormalLaw: normal::hooke::LiggghtsHooke, normal::hooke_stiffness::LiggghtsHookeStiffness, normal::hertz::LiggghtsHertz,
        normal::hertz_stiffness::LiggghtsHertzStiffness, normal::viscoelastic::PaperViscoelastic, normal::gran::LammpsGranHooke,
        normal::gran::LammpsGranHertz, normal::granular::LammpsGranular, normal::dmt::LammpsDmt, normal::jkr::LammpsJkr;
    TangentialLaw: tangential::off::LiggghtsOff, tangential::no_history::LiggghtsNoHistory, tangential::history::LiggghtsHistory, tangential::paper::PaperCundallStrack,
        tangential::gran::LammpsGranNoHistory, tangential::gran::LammpsGranHistory, tangential::granular::LammpsLinearNoHistory,
        tangential::granular::LammpsGranularHistory;
    CohesionLaw: NoCohesion, cohesion::sjkr::LiggghtsSjkr, cohesion::sjkr2::LiggghtsSjkr2, cohesion::vdw::Hamaker;
    RollingLaw: NoRolling, rolling::cdt::LiggghtsCdt, rolling::epsd::LiggghtsEpsd, rolling::epsd2::LiggghtsEpsd2, rolling::epsd3::LiggghtsEpsd3,
        rolling::paper::PaperEpsd, rolling::sds::LammpsSds, rolling::marshall::LammpsTwistMarshall, rolling::marshall::LammpsSdsMarshall;
}

#[cfg(test)]
mod tests {
    /// Every law implemented under `src/physics` is in [`check_flip`]'s list.
    #[test]
    fn flip_check_lists_every_law() {
        fn walk(dir: &std::path::Path, found: &mut Vec<String>) {
            for e in std::fs::read_dir(dir).unwrap() {
                let path = e.unwrap().path();
                if path.is_dir() {
                    walk(&path, found);
                } else if path.extension().is_some_and(|x| x == "rs") {
                    for line in std::fs::read_to_string(&path).unwrap().lines() {
                        let words: Vec<&str> = line.split_whitespace().collect();
                        if let ["impl", law, "for", ty, ..] = words[..] {
                            if ["NormalLaw", "TangentialLaw", "CohesionLaw", "RollingLaw"].contains(&law) {
                                found.push(format!("{}: {ty}", path.display()));
                            }
                        }
                    }
                }
            }
        }
        let mut found = vec![];
        walk(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/physics"), &mut found);
        assert!(found.len() >= 30, "{found:?}");
        for f in &found {
            let ty = f.rsplit(' ').next().unwrap();
            assert!(super::CHECKED_LAWS.iter().any(|c| c.rsplit("::").next().unwrap().replace(' ', "") == ty), "{f} is not in check_flip!");
        }
    }
}
