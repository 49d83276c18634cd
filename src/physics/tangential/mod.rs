//! tangential laws.
