//! Material mixing rules.
