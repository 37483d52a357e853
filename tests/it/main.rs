//! The integration tests: one crate, a headless `App` with `MinimalPlugins` driven in fixed
//! steps.

mod assets;
mod court;
mod determinism;
mod experiments;
mod gait;
mod outcome;
mod rigid;
mod steering;
mod support;
mod switching;
