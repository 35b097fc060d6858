//! Scenario files (TOML): the types, parsing with field paths in every error, and `--set path=value`
//! overrides applied to the parsed TOML before it is read into the types.
//!
//! The format is documented key by key in `docs/scenario-format.md`. Every table rejects unknown keys.
//! Reading goes TOML text → `toml::Table` (syntax errors with line and column) → overrides → a check
//! that no number is NaN or infinite → [`Scenario`] (type errors name the key's path, e.g.
//! `divisions[0].basis.order`). Physical validation and conversion to the engine's types are the build
//! layer's (`build`, above this module).
//!
//! - `types`: the scenario's types, each table a struct, with their defaults;
//! - `parse`: TOML text → table → [`Scenario`], the finite-number check, and back to TOML;
//! - `path`: key paths (`divisions[0].basis.order`): parsing, rendering, lookup;
//! - `overrides`: `--set path=value` applied to the parsed table;
//! - `tensions`: the tendon tensions of a scenario, read and set;
//! - `input_file`: errors of input paths that are not regular files.

mod input_file;
mod overrides;
mod parse;
mod path;
mod tensions;
#[cfg(test)]
mod tests;
mod types;

pub use input_file::{check_regular_file, read_error};
pub use overrides::{apply_override, MAX_OVERRIDE_SEGMENTS};
pub use parse::{from_table, parse_table};
pub use path::{every_entry, lookup, number_at, parse_path, render_path, Seg};
pub use tensions::tensions_for;
pub use types::{
    default_pulse_axis, BaseSpec, BasisKind, BasisSpec, BodySpec, DistributedKind,
    DistributedLoadSpec, DivisionSpec, InertiaSpec, LoadsSpec, MaterialSpec, ModeOrders,
    OutputSpec, PointLoadSpec, QuadratureSpec, Scenario, SectionShapeSpec, StrainMode, TendonSpec,
};
