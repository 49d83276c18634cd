//! cohesion laws.
