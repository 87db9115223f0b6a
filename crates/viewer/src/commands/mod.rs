//! The subcommands: `viewer render`, `convert`, `ies`, `lux`, `report`, `bench`, `bench-load` and `tile`. Each
//! module has the command's arguments (a clap `Args` struct) and its `run`.

pub mod bench;
pub mod bench_load;
pub mod bench_tiles;
pub mod convert;
pub mod ies;
pub mod lux;
pub mod render;
pub mod report;
pub mod tile;
pub mod tour;
