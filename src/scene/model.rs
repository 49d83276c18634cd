//! The contact model: `pair_style`, `pair_coeff`, `fix property/global`, and
//! the walls that share the model (`fix wall/gran`). The kernel for a scene is
//! chosen here, once: [`build_kernel`] walks the four model axes with one
//! generic function per axis, so every combination compiles and the chosen
//! one carries no per-contact branch on effects the scene does not use.

use super::args::{bad_keyword, parse_f64, Args};
use super::Session;
use crate::engine::kernel::{ContactKernel, Laws, ParamTable};
use crate::engine::sim::{Dialect, PairModel};
use crate::error::{Error, Result};
use crate::physics::normal::{
    self,
    granular::{GranularDamping, GranularNormal},
};
use crate::physics::tangential::{self, granular::GranularTangential};
use crate::physics::{CohesionLaw, NoCohesion, NoRolling, NormalLaw, PairParams, RollingLaw, TangentialLaw};
use crate::script::{Command, Span, Word};

/// Normal law of a scene.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum NormalSpec {
    /// LIGGGHTS `model hooke`.
    LigHooke {
        /// `ktToKnUser on`.
        kt_to_kn: bool,
    },
    /// LIGGGHTS `model hooke/stiffness`.
    LigHookeStiffness {
        /// `absolute_damping on`.
        absolute: bool,
    },
    /// LIGGGHTS `model hertz`.
    LigHertz,
    /// LIGGGHTS `model hertz/stiffness`.
    LigHertzStiffness,
    /// demx `model hertz/viscoelastic` (the angle-of-repose paper, Eq. 10).
    PaperViscoelastic,
    /// LAMMPS `gran/hooke*`.
    GranHooke,
    /// LAMMPS `gran/hertz/history`.
    GranHertz,
    /// LAMMPS `pair_style granular`.
    #[serde(skip)]
    Granular(GranularNormal, GranularDamping),
    /// LAMMPS `pair_style granular` cohesive normal models `dmt`, `jkr`.
    #[serde(skip)]
    GranularCohesive(CohesiveNormal, GranularDamping),
}

impl NormalSpec {
    /// Whether this is a LAMMPS `pair_style granular` normal model (whose
    /// coefficients come from `pair_coeff`).
    pub fn is_lammps_granular(&self) -> bool {
        matches!(self, NormalSpec::Granular(..) | NormalSpec::GranularCohesive(..))
    }
}

/// Cohesive normal sub-models of LAMMPS `pair_style granular`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CohesiveNormal {
    /// `dmt E eta nu gamma`.
    Dmt,
    /// `jkr E eta nu gamma`.
    Jkr,
}

/// Twisting sub-model of LAMMPS `pair_style granular`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum GranularTwisting {
    /// No twisting resistance (default).
    None,
    /// `twisting sds k gamma mu`.
    Sds,
    /// `twisting marshall`.
    Marshall,
}

/// Tangential law of a scene.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum TangentialSpec {
    /// LIGGGHTS `tangential off` (no tangential force).
    LigOff,
    /// LIGGGHTS `tangential no_history`.
    LigNoHistory,
    /// LIGGGHTS `tangential history`.
    LigHistory,
    /// demx `tangential history/paper` (the paper's Eq. 11).
    PaperHistory,
    /// LAMMPS `gran/hooke` (no shear history).
    GranNoHistory,
    /// LAMMPS `gran/*/history`.
    GranHistory,
    /// LAMMPS granular `linear_nohistory`.
    LinearNoHistory,
    /// LAMMPS granular history models.
    #[serde(skip)]
    Granular(GranularTangential),
}

/// Cohesion law.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum CohesionSpec {
    /// None.
    Off,
    /// LIGGGHTS `cohesion sjkr`.
    Sjkr {
        /// `tangential_reduce on`.
        tangential_reduce: bool,
    },
    /// LIGGGHTS `cohesion sjkr2`.
    Sjkr2 {
        /// `tangential_reduce on`.
        tangential_reduce: bool,
    },
    /// demx `cohesion vdw` (the paper's Hamaker force, Eqs. 13-14).
    Vdw {
        /// `tangential_reduce on`: the force also lowers the normal force of
        /// the Coulomb and rolling caps (net force, as LIGGGHTS before 3.8).
        tangential_reduce: bool,
    },
}

/// Rolling law.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum RollingSpec {
    /// None.
    Off,
    /// LIGGGHTS `rolling_friction cdt`.
    Cdt,
    /// LIGGGHTS `rolling_friction epsd`.
    Epsd {
        /// `torsionTorque on`.
        torsion: bool,
    },
    /// LIGGGHTS `rolling_friction epsd2`.
    Epsd2 {
        /// `torsionTorque on`.
        torsion: bool,
    },
    /// LIGGGHTS `rolling_friction epsd3`.
    Epsd3 {
        /// `torsionTorque on`.
        torsion: bool,
    },
    /// demx `rolling_friction epsd/paper` (the paper's Eq. 15).
    PaperEpsd {
        /// `torsionTorque on`.
        torsion: bool,
    },
    /// LAMMPS granular `rolling sds` and/or a twisting model.
    Lammps {
        /// `rolling sds` given.
        rolling: bool,
        /// Twisting model.
        twisting: GranularTwisting,
    },
}

/// The declared contact model.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PairSpec {
    /// Where `pair_style` was written.
    #[serde(skip)]
    pub span: Span,
    /// Normal law.
    pub normal: NormalSpec,
    /// Tangential law.
    pub tangential: TangentialSpec,
    /// Cohesion.
    pub cohesion: CohesionSpec,
    /// Rolling.
    pub rolling: RollingSpec,
    /// LIGGGHTS `tangential_damping` (default on) / LAMMPS dampflag.
    pub tangential_damping: bool,
    /// LIGGGHTS `limitForce` / LAMMPS `limit_damping`.
    pub limit_damping: bool,
    /// LAMMPS gran/* coefficients: Kn Kt gamma_n gamma_t xmu.
    pub gran: Option<[f64; 5]>,
    /// LAMMPS granular coefficients per type pair.
    #[serde(skip)]
    pub granular: Vec<(u32, u32, PairParams)>,
    /// Whether `pair_coeff` was given.
    pub has_coeff: bool,
}

impl PairSpec {
    /// The defaults of a model block (LIGGGHTS: hertz, no tangential history,
    /// no cohesion or rolling, tangential damping on); walls pass
    /// `has_coeff = true` since they need no `pair_coeff`.
    pub fn new(span: Span, has_coeff: bool) -> PairSpec {
        PairSpec {
            span,
            normal: NormalSpec::LigHertz,
            tangential: TangentialSpec::LigNoHistory,
            cohesion: CohesionSpec::Off,
            rolling: RollingSpec::Off,
            tangential_damping: true,
            limit_damping: false,
            gran: None,
            granular: vec![],
            has_coeff,
        }
    }

    /// Model keywords of this spec that only demx knows (the paper's laws).
    pub fn demx_extensions(&self) -> Vec<&'static str> {
        let mut v = vec![];
        if self.normal == NormalSpec::PaperViscoelastic {
            v.push("model hertz/viscoelastic");
        }
        if self.tangential == TangentialSpec::PaperHistory {
            v.push("tangential history/paper");
        }
        if matches!(self.cohesion, CohesionSpec::Vdw { .. }) {
            v.push("cohesion vdw");
        }
        if let RollingSpec::PaperEpsd { .. } = self.rolling {
            v.push("rolling_friction epsd/paper");
        }
        v
    }
    /// `hertz + tangential history` etc.
    pub fn summary(&self) -> String {
        let n = match self.normal {
            NormalSpec::LigHooke { .. } => "hooke (LIGGGHTS)".to_string(),
            NormalSpec::LigHookeStiffness { .. } => "hooke/stiffness (LIGGGHTS)".into(),
            NormalSpec::LigHertz => "hertz (LIGGGHTS)".into(),
            NormalSpec::LigHertzStiffness => "hertz/stiffness (LIGGGHTS)".into(),
            NormalSpec::PaperViscoelastic => "hertz/viscoelastic (demx, paper Eq. 10)".into(),
            NormalSpec::GranHooke => "hooke (LAMMPS gran)".into(),
            NormalSpec::GranHertz => "hertz (LAMMPS gran)".into(),
            NormalSpec::Granular(m, d) => format!("{m:?} damping {d:?} (LAMMPS granular)").to_lowercase(),
            NormalSpec::GranularCohesive(m, d) => format!("{m:?} damping {d:?} (LAMMPS granular)").to_lowercase(),
        };
        let t = match self.tangential {
            TangentialSpec::LigNoHistory | TangentialSpec::GranNoHistory | TangentialSpec::LinearNoHistory => "tangential no_history".to_string(),
            TangentialSpec::LigHistory | TangentialSpec::GranHistory => "tangential history".into(),
            TangentialSpec::PaperHistory => "tangential history/paper".into(),
            TangentialSpec::LigOff => "tangential off".into(),
            TangentialSpec::Granular(g) => format!("tangential {g:?}").to_lowercase(),
        };
        let c = match self.cohesion {
            CohesionSpec::Off => "none".to_string(),
            CohesionSpec::Sjkr { .. } => "sjkr".into(),
            CohesionSpec::Sjkr2 { .. } => "sjkr2".into(),
            CohesionSpec::Vdw { tangential_reduce: false } => "vdw".into(),
            CohesionSpec::Vdw { tangential_reduce: true } => "vdw (tangential_reduce on)".into(),
        };
        let r = match self.rolling {
            RollingSpec::Off => "none".to_string(),
            RollingSpec::Cdt => "cdt".into(),
            RollingSpec::Epsd { .. } => "epsd".into(),
            RollingSpec::Epsd2 { .. } => "epsd2".into(),
            RollingSpec::Epsd3 { .. } => "epsd3".into(),
            RollingSpec::PaperEpsd { .. } => "epsd/paper".into(),
            RollingSpec::Lammps { rolling, twisting } => {
                let tw = match twisting {
                    GranularTwisting::None => "",
                    GranularTwisting::Sds => "twisting sds",
                    GranularTwisting::Marshall => "twisting marshall",
                };
                match (rolling, tw.is_empty()) {
                    (true, true) => "sds".into(),
                    (true, false) => format!("sds + {tw}"),
                    (false, _) => tw.to_string(),
                }
            }
        };
        format!("{n} + {t}; cohesion: {c}; rolling: {r}")
    }
}

// ---------------------------------------------------------------- kernel choice

/// Build the kernel for a spec: one generic step per model axis. The deck
/// language only combines laws of one engine (LIGGGHTS `pair_style gran` or
/// LAMMPS `gran/*` / `granular`), so the walk is split by dialect: every
/// combination a deck can express compiles (LIGGGHTS 5 x 3 x 4 x 6; LAMMPS
/// gran/* 2 x 2; LAMMPS granular 3 normal laws x 2 tangential x 5
/// rolling/twisting), none that no deck can express.
pub fn build_kernel(spec: &PairSpec) -> Result<Box<dyn ContactKernel>> {
    if spec.tangential == TangentialSpec::LigOff && (spec.cohesion != CohesionSpec::Off || spec.rolling != RollingSpec::Off) {
        return Err(Error::unsupported(spec.span, "tangential off with cohesion or rolling friction"));
    }
    let k = match spec.normal {
        NormalSpec::LigHooke { kt_to_kn } => lig_tangential(normal::hooke::LiggghtsHooke { kt_to_kn }, spec),
        NormalSpec::LigHookeStiffness { absolute } => {
            lig_tangential(normal::hooke_stiffness::LiggghtsHookeStiffness { absolute_damping: absolute }, spec)
        }
        NormalSpec::LigHertz => lig_tangential(normal::hertz::LiggghtsHertz, spec),
        NormalSpec::LigHertzStiffness => lig_tangential(normal::hertz_stiffness::LiggghtsHertzStiffness, spec),
        NormalSpec::PaperViscoelastic => lig_tangential(normal::viscoelastic::PaperViscoelastic, spec),
        NormalSpec::GranHooke => gran_tangential(normal::gran::LammpsGranHooke, spec),
        NormalSpec::GranHertz => gran_tangential(normal::gran::LammpsGranHertz, spec),
        NormalSpec::Granular(model, damping) => lmp_tangential(normal::granular::LammpsGranular { model, damping }, spec),
        NormalSpec::GranularCohesive(CohesiveNormal::Dmt, damping) => lmp_tangential(normal::dmt::LammpsDmt { damping }, spec),
        NormalSpec::GranularCohesive(CohesiveNormal::Jkr, damping) => lmp_tangential(normal::jkr::LammpsJkr { damping }, spec),
    };
    k.ok_or_else(|| Error::deck(spec.span, format!("contact model mixes LIGGGHTS and LAMMPS laws: {}", spec.summary())))
}

fn lig_tangential<N: NormalLaw + Send + 'static>(n: N, spec: &PairSpec) -> Option<Box<dyn ContactKernel>> {
    match spec.tangential {
        // frictionless grains: one kernel per normal law, not one per
        // cohesion and rolling law as well (each is compiled; see build_kernel)
        TangentialSpec::LigOff => Some(finish(n, tangential::off::LiggghtsOff, NoCohesion, NoRolling)),
        TangentialSpec::LigNoHistory => lig_cohesion(n, tangential::no_history::LiggghtsNoHistory, spec),
        TangentialSpec::LigHistory => lig_cohesion(n, tangential::history::LiggghtsHistory, spec),
        TangentialSpec::PaperHistory => lig_cohesion(n, tangential::paper::PaperCundallStrack, spec),
        _ => None,
    }
}

fn lig_cohesion<N: NormalLaw + Send + 'static, T: TangentialLaw + Send + 'static>(n: N, t: T, spec: &PairSpec) -> Option<Box<dyn ContactKernel>> {
    use crate::physics::cohesion::{sjkr::LiggghtsSjkr, sjkr2::LiggghtsSjkr2};
    match spec.cohesion {
        CohesionSpec::Off => lig_rolling(n, t, NoCohesion, spec),
        CohesionSpec::Sjkr { tangential_reduce } => lig_rolling(n, t, LiggghtsSjkr { tangential_reduce }, spec),
        CohesionSpec::Sjkr2 { tangential_reduce } => lig_rolling(n, t, LiggghtsSjkr2 { tangential_reduce }, spec),
        CohesionSpec::Vdw { tangential_reduce } => lig_rolling(n, t, crate::physics::cohesion::vdw::Hamaker { tangential_reduce }, spec),
    }
}

fn lig_rolling<N, T, C>(n: N, t: T, c: C, spec: &PairSpec) -> Option<Box<dyn ContactKernel>>
where
    N: NormalLaw + Send + 'static,
    T: TangentialLaw + Send + 'static,
    C: CohesionLaw + Send + 'static,
{
    use crate::physics::rolling::{cdt::LiggghtsCdt, epsd::LiggghtsEpsd, epsd2::LiggghtsEpsd2, epsd3::LiggghtsEpsd3};
    Some(match spec.rolling {
        RollingSpec::Off => finish(n, t, c, NoRolling),
        RollingSpec::Cdt => finish(n, t, c, LiggghtsCdt),
        RollingSpec::Epsd { torsion } => finish(n, t, c, LiggghtsEpsd { torsion_torque: torsion }),
        RollingSpec::Epsd2 { torsion } => finish(n, t, c, LiggghtsEpsd2 { torsion_torque: torsion }),
        RollingSpec::Epsd3 { torsion } => finish(n, t, c, LiggghtsEpsd3 { torsion_torque: torsion }),
        RollingSpec::PaperEpsd { torsion } => finish(n, t, c, crate::physics::rolling::paper::PaperEpsd { torsion_torque: torsion }),
        RollingSpec::Lammps { .. } => return None,
    })
}

/// LAMMPS `pair_style gran/*`: its own tangential laws, no rolling.
fn gran_tangential<N: NormalLaw + Send + 'static>(n: N, spec: &PairSpec) -> Option<Box<dyn ContactKernel>> {
    if spec.cohesion != CohesionSpec::Off || spec.rolling != RollingSpec::Off {
        return None;
    }
    match spec.tangential {
        TangentialSpec::GranNoHistory => Some(finish(n, tangential::gran::LammpsGranNoHistory, NoCohesion, NoRolling)),
        TangentialSpec::GranHistory => Some(finish(n, tangential::gran::LammpsGranHistory, NoCohesion, NoRolling)),
        _ => None,
    }
}

/// LAMMPS `pair_style granular`: its tangential, rolling and twisting
/// sub-models.
fn lmp_tangential<N: NormalLaw + Send + 'static>(n: N, spec: &PairSpec) -> Option<Box<dyn ContactKernel>> {
    if spec.cohesion != CohesionSpec::Off {
        return None;
    }
    match spec.tangential {
        TangentialSpec::LinearNoHistory => lmp_rolling(n, tangential::granular::LammpsLinearNoHistory, spec),
        TangentialSpec::Granular(model) => lmp_rolling(n, tangential::granular::LammpsGranularHistory { model }, spec),
        _ => None,
    }
}

fn lmp_rolling<N: NormalLaw + Send + 'static, T: TangentialLaw + Send + 'static>(n: N, t: T, spec: &PairSpec) -> Option<Box<dyn ContactKernel>> {
    use crate::physics::rolling::marshall::{LammpsSdsMarshall, LammpsTwistMarshall};
    use crate::physics::rolling::sds::LammpsSds;
    Some(match spec.rolling {
        RollingSpec::Off | RollingSpec::Lammps { rolling: false, twisting: GranularTwisting::None } => finish(n, t, NoCohesion, NoRolling),
        RollingSpec::Lammps { rolling: true, twisting: GranularTwisting::None } => finish(n, t, NoCohesion, LammpsSds { twisting: false }),
        // twisting sds alone: the rolling part sees zero coefficients and adds nothing
        RollingSpec::Lammps { twisting: GranularTwisting::Sds, .. } => finish(n, t, NoCohesion, LammpsSds { twisting: true }),
        RollingSpec::Lammps { rolling: false, twisting: GranularTwisting::Marshall } => finish(n, t, NoCohesion, LammpsTwistMarshall),
        RollingSpec::Lammps { rolling: true, twisting: GranularTwisting::Marshall } => finish(n, t, NoCohesion, LammpsSdsMarshall),
        _ => return None,
    })
}

fn finish<N, T, C, R>(normal: N, tangential: T, cohesion: C, rolling: R) -> Box<dyn ContactKernel>
where
    N: NormalLaw + Send + 'static,
    T: TangentialLaw + Send + 'static,
    C: CohesionLaw + Send + 'static,
    R: RollingLaw + Send + 'static,
{
    Box::new(Laws { normal, tangential, cohesion, rolling })
}

// ---------------------------------------------------------------- pair_style

/// `pair_style` and `pair_coeff`.
pub fn execute(s: &mut Session, cmd: &Command) -> Result<()> {
    let mut a = Args::new(cmd);
    if cmd.name() == "pair_coeff" {
        let Some(spec) = s.pair.as_mut() else {
            return Err(Error::deck(cmd.words[0].span, "pair_coeff before pair_style"));
        };
        let ti = a.word("type I")?;
        let tj = a.word("type J")?;
        spec.has_coeff = true;
        if spec.normal.is_lammps_granular() {
            let ntypes = s.sim.ntypes.max(1) as u32;
            let (ilo, ihi) = super::args::type_range(ti, ntypes)?;
            let (jlo, jhi) = super::args::type_range(tj, ntypes)?;
            let (normal, tang, roll, pp) = parse_granular_coeff(&mut a)?;
            // demx runs one granular sub-model per scene
            let first = spec.granular.is_empty();
            if !first && (normal != spec.normal || tang != spec.tangential || roll != spec.rolling) {
                return Err(Error::unsupported(cmd.span, "different pair_style granular sub-models for different type pairs"));
            }
            spec.normal = normal;
            spec.tangential = tang;
            spec.rolling = roll;
            for i in ilo..=ihi {
                for j in jlo..=jhi {
                    spec.granular.push((i, j, pp));
                    spec.granular.push((j, i, pp));
                }
            }
        } else if a.more() {
            let w = a.word("")?;
            return Err(Error::deck(w.span, format!("pair_coeff: unexpected argument '{}' for this pair style", w.text))
                .with_hint("granular pair styles of LIGGGHTS and LAMMPS gran/* take `pair_coeff * *` only"));
        }
        return Ok(());
    }
    let style = a.word("pair style")?;
    let mut spec = PairSpec::new(cmd.span, false);
    match style.text.as_str() {
        "none" => {
            s.pair = None;
            return Ok(());
        }
        "gran" => {
            s.set_dialect(Dialect::Liggghts);
            parse_liggghts_model(&mut a, &mut spec)?;
            let ext = spec.demx_extensions();
            if !ext.is_empty() {
                s.notes.push((
                    cmd.span,
                    format!(
                        "pair_style gran: {} {} (Elekes & Parteli 2021 contact model); this deck runs in demx only, LIGGGHTS 3.8 and LAMMPS reject it",
                        ext.join(", "),
                        if ext.len() == 1 { "is a demx extension" } else { "are demx extensions" }
                    ),
                ));
            }
        }
        "gran/hooke" | "gran/hooke/history" | "gran/hertz/history" => {
            let looks_legacy = a.rest().len() < 6 || a.rest().iter().take(6).any(|w| parse_f64(w).is_err() && w.text != "NULL");
            if looks_legacy {
                return Err(Error::unsupported(style.span, format!("LIGGGHTS 1.x/2.x syntax 'pair_style {}'", style.text))
                    .with_hint("LIGGGHTS 3.8 rejects it too; `demx convert DECK --to liggghts` rewrites it as `pair_style gran model ...`"));
            }
            s.set_dialect(Dialect::Lammps);
            let kn = a.f64("Kn")?;
            let kt_w = a.word("Kt")?;
            let gn = a.f64("gamma_n")?;
            let gt_w = a.word("gamma_t")?;
            let xmu = a.f64("xmu")?;
            let dampflag = a.i64("dampflag")?;
            let kt = if kt_w.text == "NULL" { 2.0 / 7.0 * kn } else { parse_f64(kt_w)? };
            let gt = if gt_w.text == "NULL" { 0.5 * gn } else { parse_f64(gt_w)? };
            if !(0..=1).contains(&dampflag) {
                return Err(a.err_prev("dampflag must be 0 or 1"));
            }
            spec.tangential_damping = dampflag == 1;
            spec.gran = Some([kn, kt, gn, if dampflag == 0 { 0.0 } else { gt }, xmu]);
            while a.more() {
                a.choice("keyword", &["limit_damping"])?;
                spec.limit_damping = true;
            }
            spec.normal = if style.text == "gran/hertz/history" { NormalSpec::GranHertz } else { NormalSpec::GranHooke };
            spec.tangential = if style.text == "gran/hooke" { TangentialSpec::GranNoHistory } else { TangentialSpec::GranHistory };
            spec.has_coeff = false;
        }
        "granular" => {
            s.set_dialect(Dialect::Lammps);
            spec.normal = NormalSpec::Granular(GranularNormal::Hertz, GranularDamping::Viscoelastic);
            spec.tangential = TangentialSpec::LinearNoHistory;
            if a.more() {
                a.f64("cutoff")?;
            }
        }
        other => {
            return Err(match other {
                "hybrid" | "hybrid/overlay" | "gran/hooke/history/omp" => Error::unsupported(style.span, format!("pair_style {other}")),
                _ => bad_keyword(style, "pair style", &["gran", "gran/hooke", "gran/hooke/history", "gran/hertz/history", "granular", "none"])
                    .with_hint("demx runs granular pair styles only"),
            })
        }
    }
    s.pair = Some(spec);
    Ok(())
}

/// LIGGGHTS `model M tangential T cohesion C rolling_friction R surface S kw v`.
pub fn parse_liggghts_model(a: &mut Args, spec: &mut PairSpec) -> Result<()> {
    a.choice("keyword", &["model"])?;
    let m = a.word("normal model")?;
    spec.normal = match m.text.as_str() {
        "hooke" => NormalSpec::LigHooke { kt_to_kn: false },
        "hooke/stiffness" => NormalSpec::LigHookeStiffness { absolute: false },
        "hertz" => NormalSpec::LigHertz,
        "hertz/stiffness" => NormalSpec::LigHertzStiffness,
        "hertz/viscoelastic" => NormalSpec::PaperViscoelastic,
        "hooke/hysteresis" | "edinburgh" | "edinburgh/stiffness" | "luding" | "thornton_ning" => {
            return Err(Error::unsupported(m.span, format!("LIGGGHTS normal model '{}'", m.text)))
        }
        _ => return Err(bad_keyword(m, "normal model", &["hooke", "hooke/stiffness", "hertz", "hertz/stiffness", "hertz/viscoelastic"])),
    };
    while a.more() {
        let k = a.word("keyword")?;
        match k.text.as_str() {
            "tangential" => {
                let t = a.word("tangential model")?;
                spec.tangential = match t.text.as_str() {
                    "off" => TangentialSpec::LigOff,
                    "no_history" => TangentialSpec::LigNoHistory,
                    "history" => TangentialSpec::LigHistory,
                    "history/paper" => TangentialSpec::PaperHistory,
                    "tan_luding" => return Err(Error::unsupported(t.span, "LIGGGHTS tangential model 'tan_luding'")),
                    _ => return Err(bad_keyword(t, "tangential model", &["off", "no_history", "history", "history/paper"])),
                };
            }
            "cohesion" => {
                let c = a.word("cohesion model")?;
                spec.cohesion = match c.text.as_str() {
                    "off" => CohesionSpec::Off,
                    "sjkr" => CohesionSpec::Sjkr { tangential_reduce: false },
                    "sjkr2" => CohesionSpec::Sjkr2 { tangential_reduce: false },
                    "vdw" => CohesionSpec::Vdw { tangential_reduce: false },
                    "easo/capillary/viscous" | "washino/capillary/viscous" => {
                        return Err(Error::unsupported(c.span, format!("cohesion model '{}'", c.text)))
                    }
                    _ => return Err(bad_keyword(c, "cohesion model", &["off", "sjkr", "sjkr2", "vdw"])),
                };
            }
            "rolling_friction" => {
                let r = a.word("rolling model")?;
                spec.rolling = match r.text.as_str() {
                    "off" => RollingSpec::Off,
                    "cdt" => RollingSpec::Cdt,
                    "epsd" => RollingSpec::Epsd { torsion: false },
                    "epsd2" => RollingSpec::Epsd2 { torsion: false },
                    "epsd3" => RollingSpec::Epsd3 { torsion: false },
                    "epsd/paper" => RollingSpec::PaperEpsd { torsion: false },
                    "luding" => return Err(Error::unsupported(r.span, "rolling_friction model 'luding'")),
                    _ => return Err(bad_keyword(r, "rolling_friction model", &["off", "cdt", "epsd", "epsd2", "epsd3", "epsd/paper"])),
                };
            }
            "surface" => {
                let sfc = a.word("surface model")?;
                match sfc.text.as_str() {
                    "default" => {}
                    "multicontact" | "superquadric" => return Err(Error::unsupported(sfc.span, format!("surface model '{}'", sfc.text))),
                    _ => return Err(bad_keyword(sfc, "surface model", &["default"])),
                }
            }
            _ if model_keyword(k, a, spec)? => {}
            _ => {
                return Err(bad_keyword(
                    k,
                    "pair_style gran keyword",
                    &[
                        "tangential",
                        "cohesion",
                        "rolling_friction",
                        "surface",
                        "tangential_damping",
                        "limitForce",
                        "ktToKnUser",
                        "absolute_damping",
                        "torsionTorque",
                        "tangential_reduce",
                    ],
                ))
            }
        }
    }
    Ok(())
}

/// One LIGGGHTS model keyword and its value (`tangential_damping on`,
/// `tangential_reduce on`, ...), as the pair style and `fix wall/gran` (before
/// or after the wall's geometry) take them; false when `k` is none.
pub fn model_keyword(k: &Word, a: &mut Args, spec: &mut PairSpec) -> Result<bool> {
    match k.text.as_str() {
        "tangential_damping" => spec.tangential_damping = a.yes_no("tangential_damping")?,
        "limitForce" => spec.limit_damping = a.yes_no("limitForce")?,
        "ktToKnUser" => {
            let on = a.yes_no("ktToKnUser")?;
            if let NormalSpec::LigHooke { kt_to_kn } = &mut spec.normal {
                *kt_to_kn = on;
            }
        }
        "absolute_damping" => {
            let on = a.yes_no("absolute_damping")?;
            if let NormalSpec::LigHookeStiffness { absolute } = &mut spec.normal {
                *absolute = on;
            }
        }
        "torsionTorque" => {
            let on = a.yes_no("torsionTorque")?;
            match &mut spec.rolling {
                RollingSpec::Epsd { torsion }
                | RollingSpec::Epsd2 { torsion }
                | RollingSpec::Epsd3 { torsion }
                | RollingSpec::PaperEpsd { torsion } => *torsion = on,
                _ => {}
            }
        }
        "tangential_reduce" => {
            let on = a.yes_no("tangential_reduce")?;
            match &mut spec.cohesion {
                CohesionSpec::Sjkr { tangential_reduce } | CohesionSpec::Sjkr2 { tangential_reduce } | CohesionSpec::Vdw { tangential_reduce } => {
                    *tangential_reduce = on
                }
                _ => {}
            }
        }
        "heating_normal_hertz" | "computeDissipatedEnergy" | "computeElasticPotential" | "disableNormalWhenBonded" => {
            let v = a.yes_no(&k.text.clone())?;
            if v && k.text != "computeDissipatedEnergy" && k.text != "computeElasticPotential" {
                return Err(Error::unsupported(k.span, format!("model option {} on", k.text)));
            }
        }
        "viscous" => return Err(Error::unsupported(k.span, "hooke model option viscous")),
        _ => return Ok(false),
    }
    Ok(true)
}

/// One LAMMPS granular `pair_coeff` as parsed: normal, tangential and
/// rolling/twisting choices and the pair's coefficients.
type GranularChoice = (NormalSpec, TangentialSpec, RollingSpec, PairParams);

/// LAMMPS `pair_coeff I J <normal> ... tangential ... [damping ...] [rolling ...] [twisting ...] [limit_damping]`.
fn parse_granular_coeff(a: &mut Args) -> Result<GranularChoice> {
    let mut pp = PairParams::default();
    let m = a.word("normal model")?;
    // None: hooke/hertz/hertz-material family; Some: dmt, jkr
    let (model, cohesive) = match m.text.as_str() {
        "hooke" => (GranularNormal::Hooke, None),
        "hertz" => (GranularNormal::Hertz, None),
        "hertz/material" => (GranularNormal::HertzMaterial, None),
        "dmt" => (GranularNormal::HertzMaterial, Some(CohesiveNormal::Dmt)),
        "jkr" => (GranularNormal::HertzMaterial, Some(CohesiveNormal::Jkr)),
        _ => return Err(bad_keyword(m, "normal model", &["hooke", "hertz", "hertz/material", "dmt", "jkr"])),
    };
    let mut e_young = 0.0;
    let mut poisson = 0.0;
    match model {
        GranularNormal::HertzMaterial => {
            e_young = a.f64("E")?;
            pp.gamma_n = a.f64("damping")?;
            poisson = a.f64("poisson")?;
            pp.poisson = poisson;
            // E_eff for `pair_coeff` of identical materials: E / (2 (1 - nu^2)); k_n = 4/3 E_eff
            pp.y_eff = e_young / (2.0 * (1.0 - poisson * poisson));
            pp.kn = 4.0 / 3.0 * pp.y_eff;
            if cohesive.is_some() {
                let g = a.word("surface energy gamma")?;
                pp.cohesion = parse_f64(g)?;
                if !(pp.cohesion >= 0.0) || !pp.cohesion.is_finite() {
                    return Err(Error::deck(g.span, format!("{}: surface energy {} must be >= 0", m.text, g.text)));
                }
                if !(e_young > 0.0) || !e_young.is_finite() || !(poisson > -1.0 && poisson < 1.0) {
                    return Err(Error::deck(m.span, format!("{}: needs E > 0 and -1 < poisson < 1", m.text)));
                }
            }
        }
        _ => {
            pp.kn = a.f64("kn")?;
            pp.gamma_n = a.f64("damping")?;
        }
    }
    let mut damping = GranularDamping::Viscoelastic;
    let mut tang = None;
    let mut rolling = false;
    let mut twisting = GranularTwisting::None;
    while a.more() {
        let k = a.word("keyword")?;
        match k.text.as_str() {
            "tangential" => {
                let t = a.word("tangential model")?;
                let g = |x| TangentialSpec::Granular(x);
                let spec = match t.text.as_str() {
                    "linear_nohistory" => {
                        pp.gamma_t = a.f64("x_gamma_t")?;
                        pp.mu = a.f64("mu")?;
                        TangentialSpec::LinearNoHistory
                    }
                    "linear_history" | "mindlin" | "mindlin_rescale" | "mindlin/force" | "mindlin_rescale/force" => {
                        let ktw = a.word("kt")?;
                        let model = match t.text.as_str() {
                            "linear_history" => GranularTangential::LinearHistory,
                            "mindlin" => GranularTangential::Mindlin,
                            "mindlin_rescale" => GranularTangential::MindlinRescale,
                            "mindlin/force" => GranularTangential::MindlinForce,
                            _ => GranularTangential::MindlinRescaleForce,
                        };
                        pp.kt = if ktw.text == "NULL" {
                            if model == GranularTangential::LinearHistory || e_young == 0.0 {
                                return Err(Error::deck(ktw.span, "kt NULL needs a material normal model (hertz/material, dmt, jkr)"));
                            }
                            // 8 G_eff with G = E / (2 (1 + nu)), identical materials
                            let g = e_young / (2.0 * (1.0 + poisson));
                            8.0 / (2.0 * (2.0 - poisson) / g)
                        } else {
                            parse_f64(ktw)?
                        };
                        pp.gamma_t = a.f64("x_gamma_t")?;
                        pp.mu = a.f64("mu")?;
                        g(model)
                    }
                    _ => {
                        return Err(bad_keyword(
                            t,
                            "tangential model",
                            &["linear_nohistory", "linear_history", "mindlin", "mindlin_rescale", "mindlin/force", "mindlin_rescale/force"],
                        ))
                    }
                };
                tang = Some(spec);
            }
            "damping" => {
                let d = a.word("damping model")?;
                damping = match d.text.as_str() {
                    "velocity" => GranularDamping::Velocity,
                    "mass_velocity" => GranularDamping::MassVelocity,
                    "viscoelastic" => GranularDamping::Viscoelastic,
                    "tsuji" => GranularDamping::Tsuji,
                    "coeff_restitution" => return Err(Error::unsupported(d.span, "damping coeff_restitution (not in LAMMPS 29 Sep 2021)")),
                    _ => return Err(bad_keyword(d, "damping model", &["velocity", "mass_velocity", "viscoelastic", "tsuji"])),
                };
            }
            "rolling" => {
                let r = a.word("rolling model")?;
                match r.text.as_str() {
                    "none" => rolling = false,
                    "sds" => {
                        pp.k_roll = a.f64("k_roll")?;
                        pp.gamma_roll = a.f64("gamma_roll")?;
                        pp.mu_r = a.f64("mu_roll")?;
                        rolling = true;
                    }
                    _ => return Err(bad_keyword(r, "rolling model", &["none", "sds"])),
                }
            }
            "twisting" => {
                let t = a.word("twisting model")?;
                twisting = match t.text.as_str() {
                    "none" => GranularTwisting::None,
                    "sds" => {
                        pp.k_twist = a.f64("k_twist")?;
                        pp.gamma_twist = a.f64("gamma_twist")?;
                        pp.mu_twist = a.f64("mu_twist")?;
                        GranularTwisting::Sds
                    }
                    "marshall" => GranularTwisting::Marshall,
                    _ => return Err(bad_keyword(t, "twisting model", &["none", "sds", "marshall"])),
                };
            }
            "limit_damping" => {
                if let Some(c) = cohesive {
                    // LAMMPS 29 Sep 2021: "Cannot limit damping with DMT model" / "... JKR model"
                    return Err(Error::deck(
                        k.span,
                        format!("Cannot limit damping with {} model", if c == CohesiveNormal::Dmt { "DMT" } else { "JKR" }),
                    ));
                }
                pp.limit_damping = 1.0
            }
            "cutoff" => {
                a.f64("cutoff")?;
            }
            _ => return Err(bad_keyword(k, "pair_coeff keyword", &["tangential", "damping", "rolling", "twisting", "limit_damping", "cutoff"])),
        }
    }
    let Some(tang) = tang else {
        return Err(Error::deck(a.end_span(), "pair_coeff: the tangential model is required for pair_style granular"));
    };
    if damping == GranularDamping::Tsuji {
        // alpha(e) from the restitution given as the damping coefficient (LAMMPS doc)
        let e = pp.gamma_n;
        pp.gamma_n = 1.2728 - 4.2783 * e + 11.087 * e * e - 22.348 * e.powi(3) + 27.467 * e.powi(4) - 18.022 * e.powi(5) + 4.8218 * e.powi(6);
    }
    pp.tangential_damping = 1.0;
    let normal = match cohesive {
        None => NormalSpec::Granular(model, damping),
        Some(c) => NormalSpec::GranularCohesive(c, damping),
    };
    let roll = if rolling || twisting != GranularTwisting::None { RollingSpec::Lammps { rolling, twisting } } else { RollingSpec::Off };
    Ok((normal, tang, roll, pp))
}

// ---------------------------------------------------------------- materials

/// Values of a `fix property/global` entry as a matrix lookup.
fn prop<'a>(s: &'a Session, name: &str) -> Option<&'a Vec<f64>> {
    s.props.get(name).map(|(_, v)| v)
}

/// Fill the coefficient table for particle types (and the same table serves
/// LIGGGHTS walls: wall type T uses row T).
pub fn fill_table(s: &Session, spec: &PairSpec, span: Span) -> Result<ParamTable> {
    let nt = s.sim.ntypes.max(1);
    let mut t = ParamTable::new(nt);
    match spec.normal {
        NormalSpec::GranHooke | NormalSpec::GranHertz => {
            let [kn, kt, gn, gt, mu] = spec.gran.unwrap_or_default();
            for p in t.params.iter_mut() {
                p.kn = kn;
                p.kt = kt;
                p.gamma_n = gn;
                p.gamma_t = gt;
                p.mu = mu;
                p.tangential_damping = if spec.tangential_damping { 1.0 } else { 0.0 };
                p.limit_damping = if spec.limit_damping { 1.0 } else { 0.0 };
            }
        }
        NormalSpec::Granular(..) | NormalSpec::GranularCohesive(..) => {
            for &(i, j, pp) in &spec.granular {
                if (i as usize) <= nt && (j as usize) <= nt {
                    *t.get_mut(i, j) = pp;
                }
            }
            // JKR keeps a contact beyond touching, but LAMMPS 29 Sep 2021 lists
            // pairs by radii + skin only (its `size` neighbour lists; the
            // pull-off term of init_one's cutoff is negative and only sizes
            // the bins): a stretched contact ends at delta_c or when a rebuild
            // drops the pair (r > ri + rj + skin), whichever comes first
            // (verified with neighbor 1e-8: lmp loses the contact at once
            // when the overlap turns negative). demx lists pairs the same way,
            // so no extra range here.
        }
        _ => {
            use crate::physics::mixing::{liggghts_pair_params, LiggghtsMaterials, LiggghtsSettings};
            let per_type = |name: &str| prop(s, name).cloned();
            // peratomtypepair values are stored as [N, v11, v12, ...]
            let per_pair = |name: &str| -> Result<Option<Vec<f64>>> {
                match prop(s, name).or_else(|| prop(s, &format!("{name}_abs"))) {
                    None => Ok(None),
                    Some(v) => {
                        let n = v.first().copied().unwrap_or(0.0) as usize;
                        if n != nt || v.len() != 1 + n * n {
                            return Err(Error::deck(
                                span,
                                format!("property/global {name} must be `peratomtypepair {nt}` followed by {} values", nt * nt),
                            ));
                        }
                        Ok(Some(v[1..].to_vec()))
                    }
                }
            };
            let scalar = |name: &str| prop(s, name).and_then(|v| v.first().copied());
            let m = LiggghtsMaterials {
                n_types: nt,
                youngs: per_type("youngsModulus"),
                poisson: per_type("poissonsRatio"),
                restitution: per_pair("coefficientRestitution")?,
                friction: per_pair("coefficientFriction")?,
                rolling_friction: per_pair("coefficientRollingFriction")?,
                rolling_damping: per_pair("coefficientRollingViscousDamping")?,
                cohesion_energy_density: per_pair("cohesionEnergyDensity")?,
                char_vel: scalar("characteristicVelocity"),
                rolling_stiffness: scalar("rollingStiffness"),
                kn: per_pair("kn")?,
                kt: per_pair("kt")?,
                gamman: per_pair("gamman")?,
                gammat: per_pair("gammat")?,
            };
            let stiff = matches!(spec.normal, NormalSpec::LigHookeStiffness { .. } | NormalSpec::LigHertzStiffness);
            let mut needed: Vec<(&str, bool)> = vec![];
            if stiff {
                needed.extend([("kn", m.kn.is_some()), ("kt", m.kt.is_some()), ("gamman", m.gamman.is_some()), ("gammat", m.gammat.is_some())]);
            } else {
                needed.extend([
                    ("youngsModulus", m.youngs.is_some()),
                    ("poissonsRatio", m.poisson.is_some()),
                    ("coefficientRestitution", m.restitution.is_some()),
                ]);
            }
            // `tangential off` reads no friction (LIGGGHTS 3.8 runs such a
            // deck without coefficientFriction)
            if spec.tangential != TangentialSpec::LigOff {
                needed.push(("coefficientFriction", m.friction.is_some()));
            }
            if matches!(spec.normal, NormalSpec::LigHooke { .. }) {
                needed.push(("characteristicVelocity", m.char_vel.is_some()));
            }
            if matches!(spec.cohesion, CohesionSpec::Sjkr { .. } | CohesionSpec::Sjkr2 { .. }) {
                needed.push(("cohesionEnergyDensity", m.cohesion_energy_density.is_some()));
            }
            let surface_energy = per_pair("surfaceEnergy")?;
            if spec.normal == NormalSpec::PaperViscoelastic {
                needed.push(("restitutionReferenceVelocity", scalar("restitutionReferenceVelocity").is_some()));
            }
            if matches!(spec.cohesion, CohesionSpec::Vdw { .. }) {
                needed.push(("surfaceEnergy", surface_energy.is_some()));
                needed.push(("vdwMinDistance", scalar("vdwMinDistance").is_some()));
                needed.push(("vdwCutoff", scalar("vdwCutoff").is_some()));
            }
            if !matches!(spec.rolling, RollingSpec::Off) {
                needed.push(("coefficientRollingFriction", m.rolling_friction.is_some()));
            }
            if matches!(spec.rolling, RollingSpec::Epsd { .. } | RollingSpec::Epsd3 { .. }) {
                needed.push(("coefficientRollingViscousDamping", m.rolling_damping.is_some()));
            }
            if matches!(spec.rolling, RollingSpec::Epsd3 { .. }) {
                // LIGGGHTS 3.8's rolling_model_epsd3.h reads `rollingStiffness`
                // (a scalar); its documentation names it coeffRollingStiffness,
                // which the engine refuses as missing
                needed.push(("rollingStiffness", m.rolling_stiffness.is_some()));
            }
            if let Some((name, _)) = needed.iter().find(|(_, have)| !have) {
                let hint = if *name == "rollingStiffness" && prop(s, "coeffRollingStiffness").is_some() {
                    "LIGGGHTS 3.8 reads the epsd3 stiffness factor as `rollingStiffness scalar C`: the name coeffRollingStiffness of its documentation is not read (the engine stops the same way)"
                } else {
                    "LIGGGHTS reads material properties from fix property/global, defined before the run"
                };
                return Err(Error::deck(span, format!("this contact model needs `fix ID all property/global {name} ...`")).with_hint(hint));
            }
            if s.units == super::Units::Si && !s.hard_particles {
                if let Some(y) = m.youngs.as_ref().and_then(|y| y.iter().cloned().find(|&v| v > 1e9)) {
                    return Err(Error::deck(span, format!("youngsModulus {y} > 1e9 needs `hard_particles yes` (as in LIGGGHTS)"))
                        .with_hint("add `hard_particles yes` before the pair_style"));
                }
            }
            let settings = LiggghtsSettings {
                tangential_damping: spec.tangential_damping,
                limit_force: spec.limit_damping,
                units_si: s.units == super::Units::Si && !s.soft_particles,
            };
            let mut table = liggghts_pair_params(&m, &settings, span)?;
            if spec.normal == NormalSpec::PaperViscoelastic {
                let v_ref = scalar("restitutionReferenceVelocity").unwrap_or(0.0);
                let exact = scalar("restitutionExact").unwrap_or(0.0) != 0.0;
                for p in table.iter_mut() {
                    p.beta = crate::physics::mixing::mp_beta(p.restitution, v_ref, exact).ok_or_else(|| {
                        Error::deck(span, format!("hertz/viscoelastic: coefficientRestitution {} at restitutionReferenceVelocity {v_ref} gives no damping constant (need 0 < e <= 1, v > 0)", p.restitution))
                    })?;
                }
            }
            if matches!(spec.cohesion, CohesionSpec::Vdw { .. }) {
                let d_min = scalar("vdwMinDistance").unwrap_or(0.0);
                let d_max = scalar("vdwCutoff").unwrap_or(0.0);
                if !(d_min > 0.0) || !(d_max >= 0.0) || !d_min.is_finite() || !d_max.is_finite() {
                    return Err(Error::deck(span, format!("cohesion vdw: vdwMinDistance {d_min} must be > 0 and vdwCutoff {d_max} >= 0")));
                }
                let gamma = surface_energy.unwrap_or_default();
                for (p, &g) in table.iter_mut().zip(gamma.iter()) {
                    if !(g >= 0.0) || !g.is_finite() {
                        return Err(Error::deck(span, format!("cohesion vdw: surfaceEnergy {g} must be >= 0")));
                    }
                    p.cohesion = g;
                    p.d_min = d_min;
                    p.d_max = d_max;
                    p.hamaker = crate::physics::mixing::hamaker_constant(g, d_min);
                    p.extra_range = if g > 0.0 { d_max } else { 0.0 };
                }
            }
            for i in 1..=nt {
                for j in 1..=nt {
                    *t.get_mut(i as u32, j as u32) = table[(i - 1) * nt + (j - 1)];
                }
            }
        }
    }
    // demx run --youngs-scale: every stiffness divided (pairs and walls)
    super::overrides::scale_table(s, &mut t);
    Ok(t)
}

/// Before a run: build the kernel and coefficient table from the spec.
pub fn finalize(s: &mut Session, _cmd: &Command) -> Result<()> {
    let Some(spec) = s.pair.clone() else {
        s.sim.model = None;
        return Ok(());
    };
    if spec.normal.is_lammps_granular() && spec.granular.is_empty() {
        return Err(Error::deck(spec.span, "pair_style granular needs pair_coeff lines"));
    }
    if !spec.has_coeff && !matches!(spec.normal, NormalSpec::GranHooke | NormalSpec::GranHertz) {
        return Err(Error::deck(spec.span, "all pair coeffs are not set").with_hint("add `pair_coeff * *` after pair_style"));
    }
    let table = fill_table(s, &spec, spec.span)?;
    let kernel = build_kernel(&spec)?;
    s.sim.model = Some(PairModel { kernel, table, summary: spec.summary() });
    Ok(())
}

// ---------------------------------------------------------------- fixes that need the model

/// `fix property/global`, `property/atom`, `check/timestep/gran`,
/// `enforce2d`, `momentum` (the fix styles [`super::fix_styles`] sends here).
pub fn fix_command(s: &mut Session, cmd: &Command, id: &str, style: &Word, a: &mut Args) -> Result<()> {
    match style.text.as_str() {
        "property/global" => {
            let name = a.word("property name")?;
            let kind = a.choice("property style", &["scalar", "vector", "peratomtype", "peratomtypepair", "atomtype", "atomtypepair", "matrix"])?;
            let mut vals = vec![];
            for w in a.rest() {
                vals.push(parse_f64(w)?);
            }
            if vals.is_empty() {
                return Err(Error::deck(a.end_span(), format!("property/global {}: no values", name.text)));
            }
            let _ = id;
            s.props.insert(name.text.clone(), (kind.text.clone(), vals));
            Ok(())
        }
        "property/atom" if a.rest().get(1).is_none_or(|w| !matches!(w.text.as_str(), "scalar" | "vector")) => {
            Err(Error::unsupported(style.span, "LAMMPS-style fix property/atom (mol, q, i_/d_ per-atom properties)"))
        }
        "property/atom" => {
            let name = a.word("property name")?;
            a.choice("style", &["scalar", "vector"])?;
            a.word("restart yes/no")?;
            a.word("communicate yes/no")?;
            a.word("reverse yes/no")?;
            let mut vals = vec![];
            for w in a.rest() {
                vals.push(parse_f64(w)?);
            }
            s.sim.particles.add_extra(&name.text, vals);
            Ok(())
        }
        "check/timestep/gran" => {
            let every = a.i64("N")?;
            let fr = a.f64("fraction_rayleigh")?;
            let fh = a.f64("fraction_hertz")?;
            while a.more() {
                a.word("keyword")?;
            }
            let materials = (1..=s.sim.ntypes.max(1))
                .map(|t| {
                    let get = |n: &str| s.props.get(n).and_then(|(_, v)| v.get(t - 1).copied());
                    (get("youngsModulus").unwrap_or(0.0), get("poissonsRatio").unwrap_or(0.0))
                })
                .collect();
            s.add_fix(Box::new(super::fixes::CheckTimestep::new(id, every, fr, fh, materials)))
        }
        "enforce2d" | "momentum" => {
            s.notes.push((cmd.span, format!("fix {}: accepted; demx reports timestep criteria in `demx check`", style.text)));
            Ok(())
        }
        _ => Err(Error::unsupported(style.span, format!("fix {}", style.text))),
    }
}
