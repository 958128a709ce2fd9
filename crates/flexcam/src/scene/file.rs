//! The TOML scene format of the scene-and-CLI spec.
