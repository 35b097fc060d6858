//! `import gvsrom`: the gvsrom library from Python (PyO3, NumPy arrays in and out).
//!
//! Thin by design: every function converts its arguments, releases the GIL where the work is long,
//! calls the same library function the command line calls, and converts the result. Errors become
//! Python exceptions carrying the message the command line prints (`errors`); no panic crosses
//! into Python (PyO3 turns one into `PanicException`, and the library returns errors as values).

mod arrays;
mod callable;
mod compare;
mod datasets;
mod dynamics_quantities;
mod errors;
mod interrupt;
mod linearize;
mod models;
mod modes;
mod plot;
mod quantities;
mod reconstruction;
mod reduce;
mod reproduce;
mod results_pickle;
mod robot;
mod robot_pickle;
mod robot_quantities;
mod robot_statics;
mod scenario;
mod simulate;
mod simulate_args;
mod statics;
mod stepper;
mod tendon_quantities;

use pyo3::prelude::*;

/// The built-in presets: `{name: summary}` (`gvsrom presets`).
#[pyfunction]
fn presets(py: Python<'_>) -> PyResult<Bound<'_, pyo3::types::PyDict>> {
    let d = pyo3::types::PyDict::new(py);
    for p in gvsrom::presets::PRESETS {
        d.set_item(p.name, p.summary)?;
    }
    Ok(d)
}

#[pymodule]
fn _gvsrom(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(presets, m)?)?;
    errors::register(m)?;
    m.add_class::<scenario::Scenario>()?;
    m.add_class::<robot::Robot>()?;
    m.add_class::<stepper::Stepper>()?;
    m.add_class::<statics::Statics>()?;
    m.add_class::<statics::StaticsBatch>()?;
    m.add_class::<models::Model>()?;
    m.add_class::<reconstruction::Reconstruction>()?;
    m.add_function(wrap_pyfunction!(models::load_model, m)?)?;
    m.add_function(wrap_pyfunction!(reduce::pod, m)?)?;
    m.add_function(wrap_pyfunction!(reduce::train, m)?)?;
    m.add_class::<datasets::Dataset>()?;
    m.add_function(wrap_pyfunction!(datasets::dataset, m)?)?;
    m.add_function(wrap_pyfunction!(datasets::load_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(reproduce::reproduce, m)?)?;
    m.add_function(wrap_pyfunction!(plot::plot, m)?)?;
    m.add_function(wrap_pyfunction!(compare::compare, m)?)?;
    Ok(())
}
