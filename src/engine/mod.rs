//! The engine: particles (structure of arrays), domain, neighbour list with
//! contact history, the contact kernel, integration, fixes and the run loop.
pub mod particles;
pub mod domain;
pub mod neighbor;
pub mod kernel;
pub mod integrate;
pub mod fix;
pub mod compute;
pub mod output;
pub mod sim;
pub mod rng;
pub mod insert;
pub mod mesh_surface;
pub mod wind;
pub mod heat;
pub mod guard;
pub mod awake;
pub mod hugepages;
pub mod switch;

pub use sim::{Dialect, Sim};
