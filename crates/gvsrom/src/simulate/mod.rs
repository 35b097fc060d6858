//! A dynamics run of a built scenario: the actuation signal (the scenario's constant tensions, a CSV
//! file, the paper's random steps or actuator babbling), the initial state, the integrator, and the
//! trajectory written as NumPy arrays.
//!
//! The samples stream to disk as they are computed (memory does not grow with the run's length),
//! through [`crate::output`]: into a hidden staging directory beside `DIR`, moved into place at the
//! end. A run that fails or is interrupted (SIGINT/SIGTERM) still writes the samples computed so far,
//! with `"complete": false`, the reason and the last time reached in `meta.json`.
//!
//! | file | shape | content |
//! |---|---|---|
//! | `t.npy` | (N,) | sample times \[s\] |
//! | `q.npy`, `qd.npy` | (N, n) | generalized coordinates and velocities |
//! | `u.npy` | (N, n_a) | tendon tensions \[N\] |
//! | `tip_position.npy` | (N, 3) | tip position \[m\] |
//! | `tip_rotation.npy` | (N, 3, 3) | tip rotation matrices (section → world) |
//! | `strain.npy` | (N, p, 6) | ξ at the p computational points, `[torsion, bend-y, bend-z, elongation, shear-y, shear-z]` |
//! | `strain_x.npy` | (p,) | abscissae of the computational points \[m\] |
//! | `centerline.npy` | (N, c, 3) | centreline positions \[m\] at the `c` abscissae `centerline_x` of `meta.json`, at equally spaced material abscissae X (the undeformed arc length) from base to tip (`output.centerline_points`, `--centerline-points`), in the world frame as `statics --json` |
//! | `tendon_paths.npy` | (N, n_a, c, 3) | each tendon's thread `r + R d(X)` \[m\] at `centerline_x` clamped to its span (with tendons only) |
//! | `tendon_lengths.npy` | (N, n_a) | each tendon's length \[m\] along its thread, `∫ ‖t_u‖ dX` (with tendons only; at rest: `meta.json`'s `tendon_rest_lengths`) |
//! | `body_positions.npy` | (N, n_b, 2, 3) | each rigid body's section (`[:, :, 0]`) and centre of mass (`[:, :, 1]`) \[m\] (with `[[bodies]]` only; their count `n_bodies` in `meta.json`) |
//! | `meta.json` | | manifest (`gvsrom`: format, version, files), scenario, `complete`, `reason`, `t_reached`, `t_requested`, `sample_rate`, sizes, integrator statistics, wall time, real-time factor, error, `input` ([`input_record`]), `physics` (material, geometry, base, tendon routing, loads), `centerline_x`, `tendon_rest_lengths`, `provenance` ([`crate::provenance`]) |
//!
//! The integrator is chosen here too ([`choose_integrator`]): by the rod's damping unless named,
//! as `gvsrom simulate` and `gvsrom reproduce` both do.
//!
//! Files, each using only those before it: `integrator`, `options`, `plan`, `energy` (the energy
//! balance of a conservative run), `run` (the integration loop), `centerline`, `buffer` (samples
//! in memory), `writer` (samples to a directory).

mod buffer;
mod centerline;
mod energy;
mod integrator;
mod options;
mod plan;
mod run;
mod writer;

pub use buffer::*;
pub use energy::{not_conservative, EnergyBalance, ThreadSprings, GAIN_NOTE, LOSS_NOTE};
pub use integrator::*;
pub use options::*;
pub use plan::*;
pub use run::*;
pub use writer::*;
