//! rolling laws.
