//! demx: a discrete-element engine and validator for granular materials that
//! reads LIGGGHTS and LAMMPS decks.
//!
//! Architecture (see README.md): `script` turns deck text into commands,
//! `scene` executes them into a validated simulation state, `physics` holds
//! the pure contact laws, `engine` steps particles, `io` reads and writes
//! dumps, `analysis` measures (repose, packing, comparison), `convert`
//! translates dialects, `cli` is the command line.
#![warn(missing_docs)]

pub mod analysis;
pub mod cli;
pub mod convert;
pub mod engine;
pub mod error;
pub mod geom;
pub mod io;
pub mod limits;
pub mod physics;
pub mod plot;
pub mod scene;
pub mod script;

pub use error::{Error, Result};
