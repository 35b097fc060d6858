//! # gvsrom — scenarios and runs for the GVS engine
//!
//! The library half of the `gvsrom` command: TOML scenario files ([`scenario`]), their validation and
//! conversion to the engine's model ([`build`](mod@build)), the built-in presets for the paper's robots
//! ([`presets`]), statics runs with their JSON report ([`statics`]) and the natural frequencies and
//! mode shapes about an equilibrium ([`modes`]). The binary only parses the command line, calls these
//! and prints.

pub mod build;
pub mod compare;
pub mod csv_input;
pub mod dataset;
pub mod error;
pub mod figures;
pub mod layout;
pub mod linearize;
pub mod modes;
pub mod npy;
pub mod output;
pub mod plausibility;
pub mod plot;
pub mod presets;
pub mod progress;
pub mod provenance;
pub mod reduce;
pub mod reduced_model;
pub mod reproduce;
pub mod scenario;
pub mod simulate;
pub mod statics;

pub use build::{build, Built};
pub use error::ScenarioError;
pub use scenario::Scenario;
