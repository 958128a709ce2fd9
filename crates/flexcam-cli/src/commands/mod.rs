//! The subcommands.

pub mod animate;
pub mod bench;
pub mod compare;
pub mod fit;
pub mod render;
pub mod reproject;
pub mod scene_args;
pub mod scenes;
