//! The dense reference of the statics Jacobian, kept for tests: the assembly as it was before the
//! support-aware path ([`Model::statics_jacobian_after_forward`]): every per-point product sweeps
//! all `n` columns (`J_i`, `∂y/∂q` and `Ū` stored 6 × n, `Ψ_qᵀ (…)` added by `gemm_tr` into whole
//! rows of the Jacobian), whatever the support of the basis. Without the rigid bodies' offset term
//! (`add_body_weight_offsets`): it is the reference of models without off-centre bodies.

use super::*;
use crate::lie::ad;

impl<P: StrainParam> Model<P> {
    fn dense_forward_jacobians(&self, ws: &mut Workspace) {
        ws.et.iter_mut().for_each(|et| et.complete());
        let n = self.n_dof();
        ws.jac.columns_mut(0, n).fill(0.0);
        let mut hi = 0; // J_i is zero beyond column `hi`
        for i in 0..self.disc.n_points() - 1 {
            let Some(st) = self.disc.steps[i] else {
                let (a, mut b) = ws
                    .jac
                    .columns_range_pair_mut(i * n..(i + 1) * n, (i + 1) * n..(i + 2) * n);
                b.copy_from(&a);
                continue;
            };
            let h = st.h;
            let [s1, s2] = st.sites;
            let c = self.param.columns(s1);
            hi = hi.max(c.end);
            let mut z = ws.z.columns_mut(i * n + c.start, c.len());
            match self.disc.order {
                MagnusOrder::Z4 => {
                    let p1 = ws.ev.psi_q_at(s1, &c);
                    let p2 = ws.ev.psi_q_at(s2, &c);
                    z.zip_zip_apply(&p1, &p2, |zz, a, b| *zz = 0.5 * h * (a + b));
                    let k = ZANNA_C * h * h;
                    z.gemm(k, &ad(&ws.xi[s1]), &p2, 1.0);
                    z.gemm(-k, &ad(&ws.xi[s2]), &p1, 1.0);
                }
                MagnusOrder::Z2 => {
                    z.copy_from(&ws.ev.psi_q_at(s1, &c));
                    z *= h;
                }
            }
            let et = &ws.et[i];
            // J_{i+1} = Ad⁻¹ (J_i + T Z)
            let mut t1 = ws.t1.columns_mut(0, hi);
            t1.copy_from(&ws.jac.columns(i * n, hi));
            t1.columns_mut(c.start, c.len()).gemm(
                1.0,
                &et.t,
                &ws.z.columns(i * n + c.start, c.len()),
                1.0,
            );
            let adinv = et.g.adjoint_inv();
            let mut jn = ws.jac.columns_mut((i + 1) * n, n);
            jn.fill(0.0);
            jn.columns_mut(0, hi)
                .gemm(1.0, &adinv, &ws.t1.columns(0, hi), 0.0);
        }
    }

    fn dense_backward(&self, ws: &mut Workspace, mut out: Option<&mut DMatrix<f64>>) {
        let n = self.n_dof();
        let mut t2 = Matrix6xX::zeros(n);
        let mut fbar = V6::zeros();
        if out.is_some() {
            ws.ubar.fill(0.0);
        }
        for i in (0..self.disc.n_points() - 1).rev() {
            let w1 = ws.w[i + 1];
            fbar += w1;
            if out.is_some() && w1 != V6::zeros() {
                // Ū += (coadbar(w) + [m̃_g 0; f̃_g 0]) J_{i+1}: the second term is ∂w/∂q of the
                // world-fixed loads (gravity, global wrenches), spec §7.5
                let wg = ws.wg[i + 1];
                let mut c = coadbar(&w1);
                c.fixed_view_mut::<3, 3>(0, 0)
                    .add_assign(&tilde(&V3::new(wg[0], wg[1], wg[2])));
                c.fixed_view_mut::<3, 3>(3, 0)
                    .add_assign(&tilde(&V3::new(wg[3], wg[4], wg[5])));
                ws.ubar.gemm(1.0, &c, &ws.jac.columns((i + 1) * n, n), 1.0);
            }
            let Some(st) = self.disc.steps[i] else {
                continue;
            };
            let et = &ws.et[i];
            fbar = et.g.coadjoint_mul(&fbar);
            let v = et.t_tr_mul(&fbar);
            let h = st.h;
            let [s1, s2] = st.sites;
            let k = ZANNA_C * h * h;
            match self.disc.order {
                MagnusOrder::Z4 => {
                    ws.y[s1] += v * (0.5 * h) + coad_mul(&ws.xi[s2], &v) * k;
                    ws.y[s2] += v * (0.5 * h) - coad_mul(&ws.xi[s1], &v) * k;
                }
                MagnusOrder::Z2 => ws.y[s1] += v * h,
            }
            let Some(out) = out.as_deref_mut() else {
                continue;
            };
            // Ū ← coAd Ū ;  dv = Tᵀ(Ū − coadbar(F̄) J_i) + ∂(TᵀF̄)/∂Ω Z
            let coadj: M6 = et.g.adjoint_inv().transpose();
            ws.t1.gemm(1.0, &coadj, &ws.ubar, 0.0);
            std::mem::swap(&mut ws.t1, &mut ws.ubar);
            ws.t1.copy_from(&ws.ubar);
            ws.t1
                .gemm(-1.0, &coadbar(&fbar), &ws.jac.columns(i * n, n), 1.0);
            t2.gemm(1.0, &et.t.transpose(), &ws.t1, 0.0); // t2 = dv
            let c = self.param.columns(s1);
            t2.columns_mut(c.start, c.len()).gemm(
                1.0,
                &et.d_ttf(&fbar),
                &ws.z.columns(i * n + c.start, c.len()),
                1.0,
            );
            match self.disc.order {
                MagnusOrder::Z4 => {
                    let cbv = coadbar(&v) * k;
                    // dy₁ = (h/2 + k coad_{ξ₂}) dv + k coadbar(v) Ψ_q2
                    let a1 = M6::identity() * (0.5 * h) + coad(&ws.xi[s2]) * k;
                    ws.t1.gemm(1.0, &a1, &t2, 0.0);
                    ws.t1.columns_mut(c.start, c.len()).gemm(
                        1.0,
                        &cbv,
                        &ws.ev.psi_q_at(s2, &c),
                        1.0,
                    );
                    out.rows_mut(c.start, c.len()).gemm_tr(
                        1.0,
                        &ws.ev.psi_q_at(s1, &c),
                        &ws.t1,
                        1.0,
                    );
                    // dy₂ = (h/2 − k coad_{ξ₁}) dv − k coadbar(v) Ψ_q1
                    let a2 = M6::identity() * (0.5 * h) - coad(&ws.xi[s1]) * k;
                    ws.t1.gemm(1.0, &a2, &t2, 0.0);
                    ws.t1.columns_mut(c.start, c.len()).gemm(
                        -1.0,
                        &cbv,
                        &ws.ev.psi_q_at(s1, &c),
                        1.0,
                    );
                    out.rows_mut(c.start, c.len()).gemm_tr(
                        1.0,
                        &ws.ev.psi_q_at(s2, &c),
                        &ws.t1,
                        1.0,
                    );
                }
                MagnusOrder::Z2 => {
                    out.rows_mut(c.start, c.len())
                        .gemm_tr(h, &ws.ev.psi_q_at(s1, &c), &t2, 1.0);
                }
            }
        }
    }

    /// `∂R/∂q` at `q` by the dense assembly (forward pass included).
    pub(crate) fn dense_statics_jacobian(
        &self,
        q: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
        jac: &mut DMatrix<f64>,
    ) {
        let n = self.n_dof();
        self.forward(q, ws, false);
        self.dense_forward_jacobians(ws);
        self.point_wrenches(loads, ws);
        ws.y.iter_mut().for_each(|y| *y = V6::zeros());
        // ∂y_i/∂q of every point, 6 × n each (the workspace's `dyp` holds the tendon points only)
        let mut dyp = Matrix6xX::zeros(n * self.disc.n_points());
        ws.dyp.fill(0.0);
        ws.dy_hi.fill(0);
        jac.fill(0.0);
        // elastic
        match &self.k_lin {
            Some(k) => *jac -= k,
            None => {
                for (i, p) in self.disc.points.iter().enumerate() {
                    if p.weight > 0.0 {
                        let c = self.param.columns(i);
                        let psq = ws.ev.psi_q_at(i, &c);
                        let mut dy = dyp.columns_mut(i * n + c.start, c.len());
                        for a in 0..6 {
                            let e = -self.props[i].es[a] * p.weight;
                            for j in 0..c.len() {
                                dy[(a, j)] += e * psq[(a, j)];
                            }
                        }
                    }
                }
            }
        }
        for (i, p) in self.disc.points.iter().enumerate() {
            if p.weight > 0.0 {
                ws.y[i] -= self.props[i].es.component_mul(&ws.ev.psi[i]) * p.weight;
            }
        }
        self.tendon_forces(u, ws, true);
        for (i, &slot) in self.dy_slot.iter().enumerate() {
            if slot != usize::MAX {
                let mut dy = dyp.columns_mut(i * n, n);
                dy += ws.dyp.columns(slot * n, n);
            }
        }
        for i in 0..self.disc.n_points() {
            let c = self.param.columns(i);
            let dy = dyp.columns(i * n, n);
            if dy.iter().all(|v| *v == 0.0) {
                continue;
            }
            jac.rows_mut(c.start, c.len())
                .gemm_tr(1.0, &ws.ev.psi_q_at(i, &c), &dy, 1.0);
        }
        self.dense_backward(ws, Some(jac));
        if !self.param.is_linear() {
            self.param.add_weighted_hessian(q, &ws.y, &mut ws.ev, jac);
        }
        ws.dyp.fill(0.0);
        ws.dy_hi.fill(0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::discretize::Quadrature;
    use crate::loads::{DistributedWrench, Frame, Loads, PointWrench, PulseMagnitude};
    use crate::rod::Material;
    use crate::strain::{DivisionBasis, FemDegree, LinearBasis, SigmoidBend, StrainEval};

    /// A linear basis that reports every coordinate at every site (`columns = 0..n`, `Ψ_q` stored
    /// 6 × n per site): the dense layout the support-aware assembly must reproduce.
    struct DenseColumns(LinearBasis);

    impl StrainParam for DenseColumns {
        fn n_dof(&self) -> usize {
            self.0.n_dof()
        }
        fn n_sites(&self) -> usize {
            self.0.n_sites()
        }
        fn is_linear(&self) -> bool {
            true
        }
        fn new_eval(&self) -> StrainEval {
            let (n, ns) = (self.n_dof(), self.n_sites());
            let mut ev = StrainEval::zeros(n, ns);
            for s in 0..ns {
                let c = self.0.columns(s);
                ev.psi_q
                    .columns_mut(s * n + c.start, c.len())
                    .copy_from(&self.0.phi_at(s));
            }
            ev
        }
        fn eval(&self, q: &DVector<f64>, ev: &mut StrainEval) {
            let n = self.n_dof();
            for s in 0..self.n_sites() {
                ev.psi[s] = ev.psi_q.columns(s * n, n) * q;
            }
        }
        fn eval_rate(&self, _: &DVector<f64>, _: &DVector<f64>, _: &mut StrainEval) {}
        fn add_weighted_hessian(
            &self,
            _: &DVector<f64>,
            _: &[V6],
            _: &mut StrainEval,
            _: &mut DMatrix<f64>,
        ) {
        }
    }

    fn rod() -> Rod {
        let mat = Material {
            youngs_modulus: 0.617e6,
            poisson_ratio: 0.5,
            density: 1121.0,
            damping: 1e4,
        };
        Rod::tapered(mat, 0.25, 0.0125, 0.005)
    }

    fn tendons() -> Vec<Tendon> {
        vec![
            Tendon {
                offset_start: [0.0, 0.01],
                offset_end: [0.0, 0.003],
                x_start: 0.0,
                x_end: 0.25,
                friction: 0.88,
                friction_smoothing: crate::actuation::DEFAULT_FRICTION_SMOOTHING,
                turns: 0.0,
                path: Vec::new(),
                axial_stiffness: None,
            },
            Tendon {
                offset_start: [0.006, -0.002],
                offset_end: [0.002, 0.001],
                x_start: 0.05,
                x_end: 0.2,
                friction: 0.3,
                friction_smoothing: crate::actuation::DEFAULT_FRICTION_SMOOTHING,
                turns: 0.0,
                path: Vec::new(),
                axial_stiffness: None,
            },
        ]
    }

    fn loads() -> Loads {
        Loads {
            gravity: [0.0, 2.0, -9.81],
            point: vec![
                PointWrench {
                    x: 0.25,
                    wrench: [0.001, -0.002, 0.003, 0.05, -0.1, 0.2],
                    frame: Frame::Local,
                },
                PointWrench {
                    x: 0.1,
                    wrench: [0.0, 0.01, 0.0, 0.0, 0.2, -0.1],
                    frame: Frame::Global,
                },
            ],
            distributed: vec![DistributedWrench::TriangularPulse {
                center: 0.12,
                width: 0.2,
                magnitude: 0.2,
                axis: [0.0, 1.0, 0.3],
                convention: PulseMagnitude::Peak,
            }],
        }
    }

    /// `max|a − b| / max|b|`.
    fn rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
        (a - b).amax() / b.amax()
    }

    fn pseudo_random(n: usize, a: f64) -> DVector<f64> {
        DVector::from_fn(n, |i, _| a * (((i * 7919 + 13) % 101) as f64 / 50.0 - 1.0))
    }

    /// The statics Jacobian (support-aware and dense reference), residual and `J_i` of `local`
    /// against the same basis with dense columns, to round-off.
    fn check_against_dense(disc: Discretization, basis: DivisionBasis) {
        let lb = LinearBasis::per_division(&disc, &[basis]).unwrap();
        let dense = DenseColumns(lb.clone());
        let local = Model::new(rod(), disc.clone(), lb, tendons()).unwrap();
        let dense = Model::new(rod(), disc, dense, tendons()).unwrap();
        let n = local.n_dof();
        assert!(
            (0..local.disc.n_sites()).all(|s| local.param.columns(s).len() < n),
            "the basis must have local support for this test to mean anything"
        );
        let q = pseudo_random(n, 0.3);
        let u = [-2.0, -0.7];
        let pl = local.prepare_loads(&loads()).unwrap();
        let (mut wl, mut wd) = (local.workspace(), dense.workspace());
        let (mut rl, mut rd) = (DVector::zeros(n), DVector::zeros(n));
        local.statics_residual(&q, &u, &pl, &mut wl, &mut rl);
        dense.statics_residual(&q, &u, &pl, &mut wd, &mut rd);
        assert!((&rl - &rd).amax() <= 1e-12 * rd.amax(), "residual");
        let (mut jl, mut jd, mut jref) = (
            DMatrix::zeros(n, n),
            DMatrix::zeros(n, n),
            DMatrix::zeros(n, n),
        );
        local.statics_jacobian(&q, &u, &pl, &mut wl, &mut jl);
        dense.statics_jacobian(&q, &u, &pl, &mut wd, &mut jd);
        let geo = (&wl.jac - &wd.jac).amax() / wd.jac.amax();
        assert!(geo <= 1e-12, "J_i: {geo:e}");
        let mut wr = dense.workspace();
        dense.dense_statics_jacobian(&q, &u, &pl, &mut wr, &mut jref);
        let (e1, e2) = (rel(&jl, &jref), rel(&jd, &jref));
        assert!(e1 <= 1e-12 && e2 <= 1e-12, "∂R/∂q: {e1:e}, {e2:e}");
        let (kl, kd) = (local.stiffness().unwrap(), dense.stiffness().unwrap());
        assert!(rel(kl, kd) <= 1e-12, "K");
        // a second evaluation at another q reuses the workspaces' bounds and scratch
        let q2 = pseudo_random(n, -0.2);
        local.statics_jacobian(&q2, &u, &pl, &mut wl, &mut jl);
        dense.dense_statics_jacobian(&q2, &u, &pl, &mut wr, &mut jref);
        assert!(rel(&jl, &jref) <= 1e-12, "∂R/∂q at a second q");
    }

    fn fem_all_modes(elements: usize) -> DivisionBasis {
        DivisionBasis::Fem {
            modes: [true; 6],
            elements,
            degree: FemDegree::Quadratic,
        }
    }

    #[test]
    fn fem_assembly_on_the_support_equals_the_dense_assembly() {
        let quad = Quadrature::Elements {
            elements: 5,
            gauss_per_element: 3,
        };
        for order in [MagnusOrder::Z4, MagnusOrder::Z2] {
            let disc = Discretization::new(&rod(), &[quad], order, &[0.1]).unwrap();
            check_against_dense(disc, fem_all_modes(5));
        }
    }

    #[test]
    fn fem_assembly_equals_dense_when_steps_straddle_elements() {
        // Gauss points over the whole division: Magnus steps cross element ends, so the two
        // sub-points of a step lie in different elements; linear elements, three modes.
        let disc = Discretization::new(
            &rod(),
            &[Quadrature::Gauss { n: 13 }],
            MagnusOrder::Z4,
            &[0.1, 0.25],
        )
        .unwrap();
        let b = DivisionBasis::Fem {
            modes: [false, true, true, true, false, false],
            elements: 4,
            degree: FemDegree::Linear,
        };
        check_against_dense(disc, b);
    }

    #[test]
    fn nonlinear_assembly_equals_the_dense_reference() {
        let rod = Rod::tapered(rod().material, 0.8, 0.015, 0.015);
        let disc = Discretization::new(
            &rod,
            &[Quadrature::Gauss { n: 20 }],
            MagnusOrder::Z4,
            &[0.1, 0.25],
        )
        .unwrap();
        let p = SigmoidBend::new(&disc);
        let m = Model::new(rod, disc, p, tendons()).unwrap();
        let q = DVector::from_vec(vec![1.1, 8.0, 0.45]);
        let pl = m.prepare_loads(&loads()).unwrap();
        let (mut a, mut b) = (DMatrix::zeros(3, 3), DMatrix::zeros(3, 3));
        m.statics_jacobian(&q, &[-2.0, -0.7], &pl, &mut m.workspace(), &mut a);
        m.dense_statics_jacobian(&q, &[-2.0, -0.7], &pl, &mut m.workspace(), &mut b);
        assert!(rel(&a, &b) <= 1e-12, "{:e}", rel(&a, &b));
    }
}
