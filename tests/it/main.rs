//! The integration tests, as one test binary (one link instead of one per
//! file; `cargo test --test it NAME` runs the tests whose path has NAME,
//! e.g. `checkpoint::` for one file). Each file is a module; the shared
//! helpers are in `tests/common`.
//!
//! The tests run on threads of one process: a test must not change the
//! process's state (environment, working directory, panic hook) for the
//! others; it runs `demx` as a subprocess where it needs a process of its own.

#[path = "../common/mod.rs"]
mod common;

mod aeolian_saltation;
mod aeolian_wind;
mod check_writes_nothing;
mod checkpoint;
mod cli_pipe;
mod cohesion_caps;
mod compare_dumps;
mod compare_engines;
mod compare_heap;
mod contact_atom;
mod convert_corpus;
mod convert_insert;
mod coord_atom;
mod displace_atom;
mod engine_analytic;
mod engine_incline;
mod engine_vs_reference;
mod first_run;
mod freeze_vs_lammps;
mod fused_tail;
mod fuzz_script;
mod geom_lattice;
mod geom_mesh;
mod geom_primitive;
mod geom_region;
mod granregion_vs_lammps;
mod granular_jkr;
mod group_variable;
mod heat_gran;
mod history_flip;
mod insert_pack;
mod insert_pour;
mod insert_rate;
mod io_cfmt;
mod io_data;
mod io_dump;
mod io_vtk;
mod issue_2_ave_time;
mod issue_2_corpus;
mod issue_3_restart;
mod issue_3_threads;
mod issue_4_paper_deck;
mod legacy_run;
mod massflow;
mod mesh_stress;
mod mesh_vtk;
mod mesh_walls;
mod pair_pruning;
mod paper_analysis;
mod paper_laws;
mod physics_collisions;
mod physics_laws;
mod plot;
mod pressure_tensor;
mod resume_walls;
mod saltation_templates;
mod script_interp;
mod script_vars;
mod set_type_fraction;
mod slurm;
mod stability;
mod stability_guard;
mod sweep_heap;
mod thermo_headers;
mod tradeoff;
mod trust;
mod tutorials_run;
mod velocity_create;
mod velocity_set;
mod wall_candidates;
mod wall_granular;
