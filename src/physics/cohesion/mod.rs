//! Cohesion laws (add to `fn_coh`, attractive < 0), one file per deck keyword:
//! LIGGGHTS `cohesion sjkr` ([`sjkr`]) and `sjkr2` ([`sjkr2`]). Both act only
//! in contact; with `tangential_reduce on` LIGGGHTS adds the cohesive force
//! to the normal force the friction and rolling caps use.

pub mod sjkr;
pub mod sjkr2;
pub mod vdw;
