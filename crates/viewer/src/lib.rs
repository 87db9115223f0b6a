//! `viewer`: the CPU panorama viewer, as a library the `viewer` binary and the tests use.
//!
//! * `viewer [PANORAMA]` opens the interactive window ([`window`]).
//! * `viewer render ...` renders one view to a PNG (headless).
//! * `viewer convert ...` converts between equirectangular and cube maps.
//! * `viewer ies ...` summarizes and samples an IES photometric file.
//! * `viewer bench ...` measures speed against error.
//! * `viewer bench-load ...` measures loading and panning huge (8k-32k) maps.
//! * `viewer tile ...` writes a Pannellum multires pyramid ([`tile::write_pyramid`]).
//!
//! Modules:
//! * [`cli`]: the command line; [`commands`]: one module per subcommand.
//! * [`args`]: arguments the commands share and the parsers of their values (one clap
//!   value parser for every option enum, from `lut_core::Named`).
//! * [`panorama`]: opening maps (pixel limit, partial panoramas) and cube maps.
//! * [`scene`]: a map or a cube map, and [`scene::render_scene`], the one place either
//!   is rendered.
//! * [`lighting`]: luminaires lighting a rendered room (`--light`, the panel's lights).
//! * [`heatmap`]: the error heat map as an image with its legend (`render --error-map`).
//! * [`output`]: images written atomically (format by extension, special files written
//!   into, inputs never overwritten).
//! * [`exit`]: exit statuses (0, 1 for files, 2 for usage), usage errors, standard
//!   output without panics; [`signals`]: temporary files removed on SIGINT/SIGTERM.
//! * [`tour`]: tours (Pannellum configs, Marzipano data.js): the model, readers, writer,
//!   check and hotspot markers.
//! * [`window`]: winit + softbuffer + egui, all drawn on the CPU.

#![warn(missing_docs)]

pub mod args;
pub mod assets;
pub mod cli;
pub mod commands;
pub mod exit;
pub mod heatmap;
pub mod lighting;
pub mod output;
pub mod panorama;
pub mod scene;
pub mod signals;
pub mod tour;
pub mod window;

/// `viewer tile`: the multires pyramid generator (also for benches and tests).
pub use commands::tile;
