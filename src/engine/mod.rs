//! The engine: particles (structure of arrays), domain, neighbour list with
//! contact history, the contact kernel, integration, fixes and the run loop.
pub mod awake;
pub mod compute;
pub mod domain;
pub mod fix;
pub mod guard;
pub mod heat;
pub mod hugepages;
pub mod insert;
pub mod integrate;
pub mod kernel;
pub mod mesh_surface;
pub mod neighbor;
pub mod output;
pub mod particles;
pub mod rng;
pub mod sim;
pub mod switch;
pub mod wind;

pub use sim::{Dialect, Sim};
