use super::*;
use gvs::discretize::{MagnusOrder, Quadrature};
use gvs::rod::{Material, Rod};
use gvs::strain::testing::derivative_errors;
use gvs::strain::DivisionBasis;

/// `c(z) = A tanh(B z + b)`: a one-hidden-layer map with closed-form derivatives
/// (`σ' = 1 − t²`, `σ'' = −2 t σ'`).
struct TanhMap {
    a: DMatrix<f64>,
    b: DMatrix<f64>,
    bias: DVector<f64>,
}

impl CoefficientMap for TanhMap {
    fn n_in(&self) -> usize {
        self.b.ncols()
    }
    fn n_out(&self) -> usize {
        self.a.nrows()
    }
    fn scratch_len(&self) -> usize {
        self.b.nrows()
    }
    fn eval(&self, z: &[f64], c: &mut [f64], c_z: &mut [f64], scratch: &mut [f64]) {
        let t = (&self.b * DVector::from_column_slice(z) + &self.bias).map(f64::tanh);
        scratch.copy_from_slice(t.as_slice());
        c.copy_from_slice((&self.a * &t).as_slice());
        let d = DMatrix::from_diagonal(&t.map(|t| 1.0 - t * t));
        c_z.copy_from_slice((&self.a * d * &self.b).as_slice());
    }
    fn eval_value(&self, z: &[f64], c: &mut [f64], _scratch: &mut [f64]) {
        let t = (&self.b * DVector::from_column_slice(z) + &self.bias).map(f64::tanh);
        c.copy_from_slice((&self.a * &t).as_slice());
    }
    fn eval_rate(&self, z: &[f64], zd: &[f64], c_z_dot: &mut [f64], scratch: &mut [f64]) {
        let _ = z;
        let t = DVector::from_column_slice(scratch);
        let v = &self.b * DVector::from_column_slice(zd);
        let d = DMatrix::from_fn(t.len(), t.len(), |i, j| {
            if i == j {
                -2.0 * t[i] * (1.0 - t[i] * t[i]) * v[i]
            } else {
                0.0
            }
        });
        c_z_dot.copy_from_slice((&self.a * d * &self.b).as_slice());
    }
    fn add_weighted_hessian(&self, z: &[f64], g: &[f64], out: &mut [f64], scratch: &mut [f64]) {
        let _ = z;
        let t = DVector::from_column_slice(scratch);
        let ag = self.a.transpose() * DVector::from_column_slice(g);
        let d = DMatrix::from_fn(t.len(), t.len(), |i, j| {
            if i == j {
                -2.0 * t[i] * (1.0 - t[i] * t[i]) * ag[i]
            } else {
                0.0
            }
        });
        let h = self.b.transpose() * d * &self.b;
        for (o, v) in out.iter_mut().zip(h.iter()) {
            *o += v;
        }
    }
    fn eval_motion(
        &self,
        z: &[f64],
        zd: &[f64],
        zdd: Option<&[f64]>,
        c: &mut [f64],
        c_dot: &mut [f64],
        c_acc: &mut [f64],
        scratch: &mut [f64],
    ) {
        // closed form: a = B z + b, ȧ = B ż, ä = B z̈; t = tanh a; ċ = A (σ' ȧ),
        // c̈ = A (σ' ä + σ'' ȧ²)
        let t = (&self.b * DVector::from_column_slice(z) + &self.bias).map(f64::tanh);
        scratch.copy_from_slice(t.as_slice());
        let ad = &self.b * DVector::from_column_slice(zd);
        let add = match zdd {
            Some(zdd) => &self.b * DVector::from_column_slice(zdd),
            None => DVector::zeros(t.len()),
        };
        let d1 = t.map(|t| 1.0 - t * t);
        let hd = d1.component_mul(&ad);
        let hdd = DVector::from_fn(t.len(), |i, _| {
            d1[i] * add[i] - 2.0 * t[i] * d1[i] * ad[i] * ad[i]
        });
        c.copy_from_slice((&self.a * &t).as_slice());
        c_dot.copy_from_slice((&self.a * hd).as_slice());
        c_acc.copy_from_slice((&self.a * hdd).as_slice());
    }
    fn vjp(&self, g: &[f64], out: &mut [f64], scratch: &mut [f64]) {
        let t = DVector::from_column_slice(scratch);
        let ag = self.a.transpose() * DVector::from_column_slice(g);
        let mu = DVector::from_fn(t.len(), |i, _| (1.0 - t[i] * t[i]) * ag[i]);
        out.copy_from_slice((self.b.transpose() * mu).as_slice());
    }
}

fn single_tendon_like() -> (Discretization, LinearBasis) {
    single_tendon_like_with(10)
}

/// [`single_tendon_like`] with `n` Gauss points.
fn single_tendon_like_with(n: usize) -> (Discretization, LinearBasis) {
    let rod = Rod::tapered(
        Material {
            youngs_modulus: 6.17e5,
            poisson_ratio: 0.5,
            density: 1121.0,
            damping: 0.0,
        },
        0.25,
        0.0125,
        0.005,
    );
    let disc = Discretization::new(&rod, &[Quadrature::Gauss { n }], MagnusOrder::Z4, &[]).unwrap();
    let basis = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Legendre {
            modes: [false, true, false, true, false, true],
            orders: [0, 4, 0, 3, 0, 3],
        }],
    )
    .unwrap();
    (disc, basis)
}

/// Two divisions (0.15 + 0.1 m), each with Legendre coefficients of its own on every strain
/// component: the stacked blocks are one component of one division.
fn two_division_legendre() -> (Discretization, LinearBasis) {
    let material = Material {
        youngs_modulus: 1e6,
        poisson_ratio: 0.5,
        density: 1000.0,
        damping: 0.0,
    };
    let rod = Rod {
        material,
        divisions: vec![
            gvs::rod::DivisionGeometry {
                length: 0.15,
                radius_start: 0.02,
                radius_end: 0.015,
                material: None,
                section: None,
            },
            gvs::rod::DivisionGeometry {
                length: 0.1,
                radius_start: 0.015,
                radius_end: 0.01,
                material: None,
                section: None,
            },
        ],
    };
    let q = Quadrature::Gauss { n: 4 };
    let disc = Discretization::new(&rod, &[q, q], MagnusOrder::Z4, &[]).unwrap();
    let legendre = DivisionBasis::Legendre {
        modes: [true; 6],
        orders: [1, 2, 2, 1, 1, 0],
    };
    let basis = LinearBasis::per_division(&disc, &[legendre.clone(), legendre]).unwrap();
    (disc, basis)
}

/// A `TanhMap` of `r` inputs onto the coefficients of `basis`, bound to its sites.
fn tanh_param(basis: &LinearBasis, r: usize) -> ReducedParam<TanhMap> {
    let m = basis.n_dof();
    let map = TanhMap {
        a: pattern(m, 6, r) * 0.5,
        b: pattern(6, r, 2 * r + 1),
        bias: DVector::from_fn(6, |i, _| 0.1 * i as f64 - 0.2),
    };
    ReducedParam::new(basis, map, DVector::zeros(r)).unwrap()
}

/// `Φ_s X` with the dense `Φ_s` of the basis (`6 × |cols_s|`) and `X` (`m × k`).
fn dense_phi_times(basis: &LinearBasis, s: usize, x: &DMatrix<f64>) -> DMatrix<f64> {
    let cols = basis.columns(s);
    basis.phi_at(s) * x.rows(cols.start, cols.len())
}

fn pattern(rows: usize, cols: usize, k: usize) -> DMatrix<f64> {
    DMatrix::from_fn(rows, cols, |i, j| {
        (((i * 7 + j * 13 + k) % 11) as f64 - 5.0) / 5.0
    })
}

#[test]
fn the_projection_recovers_hom_coefficients_from_point_strains() {
    let (disc, basis) = single_tendon_like();
    let layout = PointLayout::active_in(&basis, &disc);
    assert_eq!(layout.active, vec![1, 3, 5]);
    assert_eq!(layout.len(), 3 * disc.n_points());
    let pm = point_matrix(&basis, &layout);
    let p = projection(&pm).unwrap();
    let q = DVector::from_fn(basis.n_dof(), |i, _| (i as f64 * 0.37).sin());
    let x = &pm * &q;
    assert!((&p * &x - &q).amax() < 1e-12);
    assert!(projection_residual(&pm, &p, &x) < 1e-13);
    // a field outside the span (a bend-y spike at one point) is not represented
    let mut spike = DVector::zeros(layout.len());
    spike[3 * 5] = 1.0;
    assert!(projection_residual(&pm, &p, &spike) > 0.5);
}

#[test]
fn reduced_derivatives_match_central_differences() {
    let (_disc, basis) = single_tendon_like();
    let m = basis.n_dof();
    for r in [1, 2, 3] {
        let map = TanhMap {
            a: pattern(m, 6, r) * 0.5,
            b: pattern(6, r, 2 * r + 1),
            bias: DVector::from_fn(6, |i, _| 0.1 * i as f64 - 0.2),
        };
        let p = ReducedParam::new(&basis, map, DVector::zeros(r)).unwrap();
        let q = DVector::from_fn(r, |i, _| 0.3 - 0.25 * i as f64);
        let qd = DVector::from_fn(r, |i, _| 0.7 + 0.5 * i as f64);
        let e = derivative_errors(&p, &q, &qd, 1e-6);
        assert!(e.max() < 1e-6, "r = {r}: {e:?}");
    }
}

#[test]
fn the_site_products_equal_the_dense_basis_times_the_map() {
    // every product of `Φ_s` against `Φ_s` (dense, from the basis) times the map's own `c`,
    // `C_z`, `Ċ_z` and, transposed, `Σ_s Φ_sᵀ w_s` through the weighted Hessian: on per-site rows
    // of 5 (one division) and 3 (two divisions) coefficients, and for r that give one to five
    // groups of four columns (the rows' products run in windows of four groups); and on the
    // stacked blocks of one division at 10 Gauss points (a block per component, tall enough)
    for (label, (_disc, basis), stacked) in [
        ("one short division", single_tendon_like_with(5), false),
        ("two divisions", two_division_legendre(), false),
        ("one division", single_tendon_like(), true),
    ] {
        let m = basis.n_dof();
        for r in [1, 3, 4, 9, 13, 17] {
            let p = tanh_param(&basis, r);
            assert_eq!(
                matches!(p.rows, BasisRows::Stacked(_)),
                stacked,
                "{label}: stacked blocks"
            );
            let z = DVector::from_fn(r, |i, _| 0.3 - 0.05 * i as f64);
            let zd = DVector::from_fn(r, |i, _| 0.7 - 0.1 * i as f64);
            let mut ev = p.new_eval();
            p.eval(&z, &mut ev);
            p.eval_rate(&z, &zd, &mut ev);
            let w: Vec<V6> = (0..basis.n_sites())
                .map(|s| V6::from_fn(|a, _| ((s * 5 + a * 3) % 7) as f64 - 3.0))
                .collect();
            let mut h = DMatrix::zeros(r, r);
            p.add_weighted_hessian(&z, &w, &mut ev, &mut h);
            // the reference, from the map and the dense basis
            let map = p.map();
            let mut scratch = vec![0.0; map.scratch_len()];
            let (mut c, mut cz, mut czd) = (vec![0.0; m], vec![0.0; m * r], vec![0.0; m * r]);
            map.eval(z.as_slice(), &mut c, &mut cz, &mut scratch);
            map.eval_rate(z.as_slice(), zd.as_slice(), &mut czd, &mut scratch);
            let mut g = DVector::zeros(m);
            for (s, ws) in w.iter().enumerate() {
                let cols = basis.columns(s);
                let phi_t_w = basis.phi_at(s).transpose() * ws;
                let mut part = g.rows_mut(cols.start, cols.len());
                part += phi_t_w;
            }
            let mut h_ref = vec![0.0; r * r];
            map.add_weighted_hessian(z.as_slice(), g.as_slice(), &mut h_ref, &mut scratch);
            let close = |x: &[f64], y: &[f64]| {
                let scale = y.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                x.len() == y.len() && x.iter().zip(y).all(|(u, v)| (u - v).abs() <= 1e-12 * scale)
            };
            let (c, cz, czd) = (
                DMatrix::from_column_slice(m, 1, &c),
                DMatrix::from_column_slice(m, r, &cz),
                DMatrix::from_column_slice(m, r, &czd),
            );
            for s in 0..basis.n_sites() {
                let psi = dense_phi_times(&basis, s, &c);
                assert!(
                    close(ev.psi[s].as_slice(), psi.as_slice()),
                    "{label} r = {r}: Ψ at {s}"
                );
                let got = &ev.psi_q.as_slice()[6 * r * s..6 * r * (s + 1)];
                let want = dense_phi_times(&basis, s, &cz);
                assert!(close(got, want.as_slice()), "{label} r = {r}: Ψ_q at {s}");
                let got = &ev.psi_q_dot.as_slice()[6 * r * s..6 * r * (s + 1)];
                let want = dense_phi_times(&basis, s, &czd);
                assert!(close(got, want.as_slice()), "{label} r = {r}: Ψ̇_q at {s}");
            }
            assert!(
                close(h.as_slice(), &h_ref),
                "{label} r = {r}: weighted Hessian"
            );
        }
    }
}

#[test]
fn the_motion_and_strain_evaluations_and_the_projection_equal_those_from_psi_q() {
    // ξ̇_s = Ψ_q,s q̇, Ψ̇_q,s q̇ + Ψ_q,s q̈ and Σ_s Ψ_q,sᵀ w_s from eval + eval_rate (checked against
    // central differences in `reduced_derivatives_match_central_differences`) against the
    // motion evaluation's direct ones, on a one- and a two-division basis
    for (label, (_disc, basis)) in [
        ("one division", single_tendon_like()),
        ("two divisions", two_division_legendre()),
    ] {
        for r in [1, 3] {
            let p = tanh_param(&basis, r);
            let q = DVector::from_fn(r, |i, _| 0.3 - 0.25 * i as f64);
            let qd = DVector::from_fn(r, |i, _| 0.7 + 0.5 * i as f64);
            let qdd = DVector::from_fn(r, |i, _| -1.3 + 0.9 * i as f64);
            let w: Vec<V6> = (0..basis.n_sites())
                .map(|s| V6::from_fn(|a, _| ((s * 5 + a * 3) % 7) as f64 - 3.0))
                .collect();
            {
                let mut ev = p.new_eval();
                p.eval(&q, &mut ev);
                p.eval_rate(&q, &qd, &mut ev);
                let mut proj = DVector::zeros(r);
                p.project(&w, &mut ev, &mut proj);
                let mut mo = p.new_eval();
                for with_qdd in [true, false] {
                    let qdd = with_qdd.then_some(&qdd);
                    assert!(p.eval_motion(&q, &qd, qdd, &mut mo));
                    mo.motion = true;
                    mo.psi_q_stale = true;
                    let close = |x: &V6, y: &V6| (x - y).amax() <= 1e-12 * y.amax().max(1.0);
                    for s in 0..basis.n_sites() {
                        let c = 0..r;
                        let xid: V6 = ev.psi_q_at(s, &c) * &qd;
                        let mut acc: V6 = ev.psi_q_dot_at(s, &c) * &qd;
                        if let Some(qdd) = qdd {
                            acc += ev.psi_q_at(s, &c) * qdd;
                        }
                        assert!(close(&mo.psi[s], &ev.psi[s]), "{label} r = {r}: Ψ at {s}");
                        assert!(close(&mo.xi_dot[s], &xid), "{label} r = {r}: ξ̇ at {s}");
                        assert!(close(&mo.xi_acc[s], &acc), "{label} r = {r}: ξ̈ᵇ at {s}");
                    }
                    let mut sv = p.new_eval();
                    assert!(p.eval_strains(&q, &mut sv));
                    for s in 0..basis.n_sites() {
                        assert!(
                            close(&sv.psi[s], &ev.psi[s]),
                            "{label} r = {r}: Ψ alone at {s}"
                        );
                    }
                    let mut proj_mo = DVector::zeros(r);
                    p.project(&w, &mut mo, &mut proj_mo);
                    let err = (&proj_mo - &proj).amax() / proj.amax();
                    assert!(err < 1e-12, "{label} r = {r}: Σ Ψ_qᵀ w off by {err:e}");
                }
            }
        }
    }
}

#[test]
fn the_rest_point_of_a_map_is_found_from_a_rough_guess() {
    let (_disc, basis) = single_tendon_like();
    let m = basis.n_dof();
    // c(z) = A tanh(B z + b) vanishes where B z + b = 0: z* = −b/B for r = 1
    let map = TanhMap {
        a: pattern(m, 1, 3),
        b: DMatrix::from_element(1, 1, 2.0),
        bias: DVector::from_element(1, 0.6),
    };
    let (z, norm) = ReducedParam::find_rest(&map, &DVector::from_element(1, 0.4));
    assert!((z[0] + 0.3).abs() < 1e-10 && norm < 1e-10, "{z} {norm}");
    let p = ReducedParam::new(&basis, map, z.clone()).unwrap();
    assert_eq!(p.rest_coordinates(), z);
}

#[test]
fn a_map_of_the_wrong_size_is_refused() {
    let (_disc, basis) = single_tendon_like();
    let map = TanhMap {
        a: pattern(basis.n_dof() + 1, 2, 0),
        b: pattern(2, 1, 0),
        bias: DVector::zeros(2),
    };
    let e = ReducedParam::new(&basis, map, DVector::zeros(1))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("coefficients"), "{e}");
}
