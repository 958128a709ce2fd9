//! Built-in scenes (`builtin:NAME`), listed by `flexcam scenes`.
