//! The subcommands: `viewer render`, `convert`, `ies`, `lux`, `bench` and `bench-load`. Each
//! module has the command's arguments (a clap `Args` struct) and its `run`.

pub mod bench;
pub mod bench_load;
pub mod convert;
pub mod ies;
pub mod lux;
pub mod render;
