//! The subcommands.

pub mod render;
pub mod scenes;
