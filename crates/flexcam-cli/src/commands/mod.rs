//! The subcommands.

pub mod animate;
pub mod render;
pub mod scenes;
