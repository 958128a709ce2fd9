//! The subcommands.

pub mod bench;
pub mod render;
pub mod scenes;
