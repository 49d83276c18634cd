//! normal laws.
