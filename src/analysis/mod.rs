//! Measurements on runs: comparison with the reference engines, angle of
//! repose, packing fraction, aeolian transport, cost-accuracy trade-offs,
//! size-gravity sweeps of the angle of repose.
pub mod compare;
pub mod compare_deck;
pub mod compare_stats;
pub mod reference;
pub mod repose;
pub mod packing;
pub mod saltation;
pub mod sweep;
pub mod campaign;
pub mod tradeoff;
