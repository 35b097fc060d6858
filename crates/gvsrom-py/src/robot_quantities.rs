//! The model quantities of `Robot` at a state: forward kinematics, the geometric and position
//! Jacobians, the point velocities, the mass matrix `M(q)`, the static residual
//! `R(q) = −K₁(q) + F(q) + B(q)u` (paper eq. 9) and its Jacobian. Each converts its arguments,
//! checks the state ([`Robot::coordinates`]) and makes one call of [`crate::quantities`].

use crate::arrays::{self, In1, Tensions};
use crate::errors::{invalid, scenario as err};
use crate::quantities;
use crate::robot::Robot;
use pyo3::prelude::*;
use pyo3::types::PyDict;

#[pymethods]
impl Robot {
    /// Forward kinematics: the poses of the cross-sections at the computational points.
    ///
    /// Parameters
    /// ----------
    /// q : array_like of float, shape (n_dof,)
    ///
    /// Returns
    /// -------
    /// dict
    ///     ``x`` (p,) abscissae [m], ``position`` (p, 3) [m], ``rotation`` (p, 3, 3) (section →
    ///     world).
    fn forward<'py>(&self, py: Python<'py>, q: In1<'_>) -> PyResult<Bound<'py, PyDict>> {
        let q = self.coordinates(&q)?;
        let (pos, rot) = py.detach(|| quantities::forward(&self.built, &self.workspaces, &q));
        let p = self.built.model.disc.n_points();
        let d = PyDict::new(py);
        d.set_item("x", self.point_x(py))?;
        d.set_item("position", arrays::shaped(py, pos, [p, 3])?)?;
        d.set_item("rotation", arrays::shaped(py, rot, [p, 3, 3])?)?;
        Ok(d)
    }

    /// Geometric (body) Jacobian ``J_i`` of point ``i``: the section's twist is
    /// ``η_i = J_i q̇`` (angular velocity first, then linear, both in the section frame): rows
    /// 0–2 in rad/s and rows 3–5 in m/s per unit of ``q̇``.
    ///
    /// Parameters
    /// ----------
    /// q : array_like of float, shape (n_dof,)
    /// point : int, optional
    ///     Point index (negative counts from the tip); default: all points.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     Shape (6, n_dof), or (n_points, 6, n_dof) for all points.
    #[pyo3(signature = (q, point=None))]
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: In1<'_>,
        #[pyo3(from_py_with = arrays::whole_or_none)] point: Option<i128>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.built.n_dof();
        let q = self.coordinates(&q)?;
        let p = self.built.model.disc.n_points();
        let which: Vec<usize> = match point {
            None => (0..p).collect(),
            Some(i) => {
                let j = if i < 0 { i + p as i128 } else { i };
                if !(0..p as i128).contains(&j) {
                    return Err(invalid(format!(
                        "`point` = {i} is out of range: the rod has {p} points"
                    )));
                }
                vec![j as usize]
            }
        };
        let flat = py.detach(|| quantities::jacobians(&self.built, &self.workspaces, &q, &which));
        match point {
            None => arrays::shaped(py, flat, [p, 6, n]),
            Some(_) => arrays::shaped(py, flat, [6, n]),
        }
    }

    /// World position of the centreline at abscissa ``x`` and its Jacobian ``∂p/∂q`` (world
    /// axes): ``δp = J δq``, the output matrix of a position sensor or a task-space controller at
    /// ``x``. At a computational point ``J`` is ``R_i`` times rows 3–5 of ``jacobian(q, i)``;
    /// between points, the derivative of the centreline's cubic Hermite interpolant (the one
    /// ``statics`` samples). ``linearize(outputs=…)`` stacks the same rows into ``C``.
    ///
    /// Parameters
    /// ----------
    /// q : array_like of float, shape (n_dof,)
    /// x : float or array_like of float
    ///     Abscissa(e) [m] within [0, length].
    ///
    /// Returns
    /// -------
    /// tuple of numpy.ndarray
    ///     ``(position, jacobian)``: shapes (3,) and (3, n_dof) for one ``x``, (k, 3) and
    ///     (k, 3, n_dof) for k of them.
    fn position_jacobian<'py>(
        &self,
        py: Python<'py>,
        q: In1<'_>,
        x: arrays::Abscissae,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let q = self.coordinates(&q)?;
        let arrays::Abscissae { values: xs, one } = x;
        let xs = gvsrom::linearize::check_abscissae("x", &xs, self.built.model.disc.length())
            .map_err(|e| invalid(e.to_string()))?;
        let n = self.built.n_dof();
        let k = xs.len();
        let (pos, jac) =
            py.detach(|| quantities::position_jacobians(&self.built, &self.workspaces, &q, &xs));
        match one {
            true => Ok((
                arrays::shaped(py, pos, [3])?,
                arrays::shaped(py, jac, [3, n])?,
            )),
            false => Ok((
                arrays::shaped(py, pos, [k, 3])?,
                arrays::shaped(py, jac, [k, 3, n])?,
            )),
        }
    }

    /// Section twists ``η_i`` at the points (angular then linear velocity, section frame) at
    /// ``(q, q̇)``, by the engine's velocity recursion.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     Shape (n_points, 6): rad/s, then m/s.
    fn point_velocities<'py>(
        &self,
        py: Python<'py>,
        q: In1<'_>,
        qd: In1<'_>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.built.n_dof();
        let (q, qd) = (self.coordinates(&q)?, arrays::dvec("qd", &qd, n)?);
        let flat = py.detach(|| quantities::velocities(&self.built, &self.workspaces, &q, &qd));
        crate::dynamics_quantities::finite_at("the point velocities", &flat, &qd)?;
        arrays::shaped(py, flat, [self.built.model.disc.n_points(), 6])
    }

    /// The mass matrix ``M(q)`` (symmetric positive definite), shape (n_dof, n_dof):
    /// ``½ q̇ᵀ M q̇`` is the kinetic energy [J] (units: see :class:`Robot`).
    fn mass_matrix<'py>(&self, py: Python<'py>, q: In1<'_>) -> PyResult<Bound<'py, PyAny>> {
        let q = self.coordinates(&q)?;
        let m = py.detach(|| quantities::mass_matrix(&self.built, &self.workspaces, &q));
        arrays::matrix(py, &m)
    }

    /// The static residual ``R(q) = −K₁(q) + F(q) + B(q)u`` (paper eq. 9) under the scenario's
    /// loads: zero at an equilibrium. A generalized force [J per unit of q].
    ///
    /// Parameters
    /// ----------
    /// q : array_like of float, shape (n_dof,)
    /// u : array_like of float, optional
    ///     Tensions [N], one per tendon or one for all; default: the scenario's.
    #[pyo3(signature = (q, u=None))]
    fn statics_residual<'py>(
        &self,
        py: Python<'py>,
        q: In1<'_>,
        u: Option<Tensions<'_>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let q = self.coordinates(&q)?;
        let u = self.quantity_tensions(py, u)?;
        let r = py
            .detach(|| quantities::statics_residual(&self.built, &self.workspaces, &q, &u))
            .map_err(err)?;
        Ok(arrays::vector(py, r.as_slice()))
    }

    /// The analytic Jacobian ``∂R/∂q`` of :meth:`statics_residual`, shape (n_dof, n_dof)
    /// [J per unit of q²: ``δqᵀ (∂R/∂q) δq`` is in J].
    #[pyo3(signature = (q, u=None))]
    fn statics_jacobian<'py>(
        &self,
        py: Python<'py>,
        q: In1<'_>,
        u: Option<Tensions<'_>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let q = self.coordinates(&q)?;
        let u = self.quantity_tensions(py, u)?;
        let j = py
            .detach(|| quantities::statics_jacobian(&self.built, &self.workspaces, &q, &u))
            .map_err(err)?;
        arrays::matrix(py, &j)
    }

    /// Snapshot rows of absolute strains: ``ξ − ξ*`` of the components the scenario's strain
    /// basis excites, point-major (``[point 0's components…, point 1's…, …]``) — the layout of a
    /// dataset's ``strain`` rows and of :meth:`Model.encode`'s input — from the strains ``ξ`` at
    /// the computational points as :attr:`Statics.strain` and ``simulate(…)["strain"]`` give
    /// them. So a result of this robot, or of another robot of the same scenario, can be encoded:
    /// ``model.encode(robot.snapshot(eq.strain))``.
    ///
    /// Parameters
    /// ----------
    /// strain : array_like of float, shape (n_points, 6) or (k, n_points, 6)
    ///     ``[torsion, bend-y, bend-z, elongation, shear-y, shear-z]`` at each point (1/m, then
    ///     dimensionless; the unloaded rod's elongation is 1).
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     Shape (n_points · n_components,), or (k, n_points · n_components).
    fn snapshot<'py>(
        &self,
        py: Python<'py>,
        strain: arrays::InDyn<'_>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let m = &self.built.model;
        let p = m.disc.n_points();
        let v = strain.as_array();
        let shape = v.shape().to_vec();
        let k = match shape[..] {
            [rows, 6] if rows == p => None,
            [k, rows, 6] if rows == p => Some(k),
            _ => {
                let dims: Vec<String> = shape.iter().map(usize::to_string).collect();
                // NumPy's spelling: a 1-tuple keeps its comma
                let comma = if dims.len() == 1 { "," } else { "" };
                return Err(invalid(format!(
                    "`strain` has shape ({}{comma}); expected ({p}, 6) or (k, {p}, 6): the 6 strain components at each of the {p} points, as `Statics.strain` gives them",
                    dims.join(", ")
                )));
            }
        };
        let xi: Vec<f64> = v.iter().copied().collect();
        if let Some(j) = xi.iter().position(|x| !x.is_finite()) {
            return Err(invalid(format!(
                "`strain` holds {} at flat index {j}: expected finite strains",
                xi[j]
            )));
        }
        let layout = rom::reduced::PointLayout::active_in(&m.param, &m.disc);
        let mut rows = Vec::with_capacity(k.unwrap_or(1) * layout.len());
        for sample in xi.chunks_exact(6 * p) {
            for i in 0..p {
                let star = m.xi_star(i);
                rows.extend(layout.active.iter().map(|&a| sample[6 * i + a] - star[a]));
            }
        }
        match k {
            None => Ok(arrays::vector(py, &rows)),
            Some(k) => arrays::shaped(py, rows, [k, layout.len()]),
        }
    }
}
