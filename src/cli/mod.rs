//! The `orthosim` command's subcommands, one file each with its arguments, and the pieces they
//! share: value parsers for the library's named choices ([`choice`]), the sphere trees of the
//! simulation commands ([`tree_args`]) and terminal output ([`terminal`]).
//!
//! The library's errors are typed; here they meet `anyhow`, which prints one line per failure.

pub mod bench;
pub mod cases;
pub mod choice;
pub mod export_case;
pub mod inspect;
pub mod occlusion;
pub mod plan;
pub mod report;
pub mod screenshot;
pub mod simulate;
pub mod terminal;
pub mod tree_args;
pub mod trees;
pub mod validate;
pub mod view;
