//! The subcommands.

pub mod compare;
pub mod render;
pub mod scene_args;
pub mod scenes;
