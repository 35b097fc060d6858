//! Tests of the linear bases: degrees of freedom, values of the Legendre and FEM-like columns,
//! the multi-division column layout, composition and interpolation of pointwise values.

use super::*;
use crate::discretize::{MagnusOrder, Quadrature};
use crate::rod::{DivisionGeometry, Material, Rod};

fn disc(lengths: &[f64], q: Quadrature) -> Discretization {
    let rod = Rod {
        material: Material {
            youngs_modulus: 1e6,
            poisson_ratio: 0.5,
            density: 1000.0,
            damping: 0.0,
        },
        divisions: lengths
            .iter()
            .map(|&l| DivisionGeometry {
                length: l,
                radius_start: 0.01,
                radius_end: 0.01,
                material: None,
                section: None,
            })
            .collect(),
    };
    Discretization::new(&rod, &vec![q; lengths.len()], MagnusOrder::Z4, &[]).unwrap()
}

#[test]
fn paper_dof_counts() {
    let a = DivisionBasis::Legendre {
        modes: [false, true, false, true, false, true],
        orders: [0, 10, 0, 10, 0, 10],
    };
    assert_eq!(a.dofs(), 33);
    let c = DivisionBasis::Legendre {
        modes: [true; 6],
        orders: [1, 2, 2, 1, 1, 1],
    };
    assert_eq!(2 * c.dofs(), 28);
    let b = DivisionBasis::Fem {
        modes: [false, true, false, false, false, false],
        elements: 49,
        degree: FemDegree::Linear,
    };
    assert_eq!(b.dofs(), 50);
    let qd = DivisionBasis::Fem {
        modes: [true, false, false, false, false, false],
        elements: 4,
        degree: FemDegree::Quadratic,
    };
    assert_eq!(qd.dofs(), 9);
}

#[test]
fn legendre_values_and_angular_scaling() {
    let d = disc(&[0.5], Quadrature::Gauss { n: 5 });
    let b = DivisionBasis::Legendre {
        modes: [false, true, false, true, false, false],
        orders: [0, 3, 0, 2, 0, 0],
    };
    let lb = LinearBasis::per_division(&d, &[b]).unwrap();
    for (s, site) in d.sites.iter().enumerate() {
        let x = 2.0 * site.x_bar - 1.0;
        let p = [
            1.0,
            x,
            0.5 * (3.0 * x * x - 1.0),
            0.5 * (5.0 * x * x * x - 3.0 * x),
        ];
        let phi = lb.phi_at(s);
        for m in 0..4 {
            assert!((phi[(1, m)] - p[m] / 0.5).abs() < 1e-14);
        }
        for m in 0..3 {
            assert!((phi[(3, 4 + m)] - p[m]).abs() < 1e-14);
        }
        assert_eq!(phi.row(0).amax(), 0.0);
    }
}

#[test]
fn fem_hat_functions_partition_unity_and_interpolate_nodes() {
    let d = disc(
        &[0.8],
        Quadrature::Elements {
            elements: 7,
            gauss_per_element: 2,
        },
    );
    for deg in [FemDegree::Linear, FemDegree::Quadratic] {
        let b = DivisionBasis::Fem {
            modes: [false, false, false, true, false, false],
            elements: 7,
            degree: deg,
        };
        let lb = LinearBasis::per_division(&d, &[b]).unwrap();
        for s in 0..d.n_sites() {
            let sum: f64 = lb.phi_at(s).row(3).sum();
            assert!((sum - 1.0).abs() < 1e-13);
        }
        // at element ends (weight-0 points) exactly one node is 1
        for (i, p) in d.points.iter().enumerate() {
            if p.weight == 0.0 {
                let phi = lb.phi_at(i);
                assert!(
                    (phi.row(3).amax() - 1.0).abs() < 1e-12,
                    "node value at X̄ = {}",
                    p.x_bar
                );
            }
        }
    }
}

#[test]
fn multi_division_columns_are_disjoint() {
    let d = disc(&[0.3, 0.3], Quadrature::Gauss { n: 5 });
    let c = DivisionBasis::Legendre {
        modes: [true; 6],
        orders: [1, 2, 2, 1, 1, 1],
    };
    let lb = LinearBasis::per_division(&d, &[c.clone(), c]).unwrap();
    assert_eq!(lb.n_dof(), 28);
    assert_eq!(lb.columns(0), 0..14);
    assert_eq!(lb.columns(d.n_points() - 1), 14..28);
}

#[test]
fn empty_basis_is_an_error() {
    let d = disc(&[0.3], Quadrature::Gauss { n: 5 });
    let c = DivisionBasis::Legendre {
        modes: [false; 6],
        orders: [1; 6],
    };
    let e = LinearBasis::per_division(&d, &[c]).unwrap_err().to_string();
    assert!(
        e.contains("divisions[0].basis") && e.contains("empty"),
        "{e}"
    );
}

#[test]
fn a_composed_basis_is_the_product_at_every_site() {
    let d = disc(&[0.3, 0.3], Quadrature::Gauss { n: 4 });
    let c = DivisionBasis::Legendre {
        modes: [true; 6],
        orders: [1, 2, 2, 1, 1, 1],
    };
    let lb = LinearBasis::per_division(&d, &[c.clone(), c]).unwrap();
    let b = DMatrix::from_fn(28, 3, |i, j| ((i * 5 + j * 3) % 7) as f64 - 3.0);
    let pb = lb.compose(&b).unwrap();
    assert_eq!(pb.n_dof(), 3);
    let q_r = DVector::from_vec(vec![0.3, -1.2, 0.7]);
    let (mut e1, mut e2) = (lb.new_eval(), pb.new_eval());
    lb.eval(&(&b * &q_r), &mut e1);
    pb.eval(&q_r, &mut e2);
    for s in 0..d.n_sites() {
        assert!((e1.psi[s] - e2.psi[s]).amax() < 1e-13);
    }
    assert!(lb.compose(&DMatrix::zeros(27, 3)).is_err());
}

#[test]
fn point_values_are_interpolated_to_sub_points() {
    let d = disc(&[0.4], Quadrature::Gauss { n: 6 });
    // a basis linear in X is reproduced exactly at the sub-points
    let np = d.n_points();
    let mut v = DMatrix::zeros(6 * np, 1);
    for (i, p) in d.points.iter().enumerate() {
        v[(6 * i + 1, 0)] = 1.0 + 2.0 * p.x;
    }
    let lb = LinearBasis::from_point_values(&d, &v).unwrap();
    for (s, site) in d.sites.iter().enumerate() {
        assert!((lb.phi_at(s)[(1, 0)] - (1.0 + 2.0 * site.x)).abs() < 1e-13);
    }
}

#[test]
fn fem_bases_reproduce_polynomials_of_their_degree_from_nodal_values() {
    // Lagrange elements of degree d interpolate: nodal values q_k = p(X̄_k) of any polynomial p of
    // degree ≤ d give Σ_k φ_k(X̄) q_k = p(X̄) everywhere (the nodes at X̄_k = k / (d·E), ends and,
    // for quadratic elements, mid-points). A permutation of the shape functions fails this.
    let e = 5;
    let d = disc(
        &[0.8],
        Quadrature::Elements {
            elements: e,
            gauss_per_element: 3,
        },
    );
    for (deg, order) in [(FemDegree::Linear, 1usize), (FemDegree::Quadratic, 2)] {
        let p = |x: f64| match order {
            1 => 0.3 - 1.2 * x,
            _ => 0.3 - 1.2 * x + 0.7 * x * x,
        };
        let b = DivisionBasis::Fem {
            modes: [false, false, false, true, false, false],
            elements: e,
            degree: deg,
        };
        let lb = LinearBasis::per_division(&d, &[b]).unwrap();
        let nodes = order * e + 1;
        let q: Vec<f64> = (0..nodes)
            .map(|k| p(k as f64 / (order * e) as f64))
            .collect();
        assert_eq!(lb.n_dof(), nodes);
        for (i, pt) in d.points.iter().enumerate() {
            // Φ_s restricted to its columns (the element's nodes)
            let (phi, cols) = (lb.phi_at(i), lb.columns(i));
            let v: f64 = (0..phi.ncols())
                .map(|c| phi[(3, c)] * q[cols.start + c])
                .sum();
            assert!(
                (v - p(pt.x_bar)).abs() < 1e-13,
                "degree {order} at X̄ = {}: {v} against {}",
                pt.x_bar,
                p(pt.x_bar)
            );
        }
    }
    // several active modes: node-major columns, each strain row only in its own slot
    let b = DivisionBasis::Fem {
        modes: [false, true, false, true, false, false],
        elements: e,
        degree: FemDegree::Quadratic,
    };
    let lb = LinearBasis::per_division(&d, &[b]).unwrap();
    for i in 0..d.n_points() {
        let (phi, cols) = (lb.phi_at(i), lb.columns(i));
        for c in 0..phi.ncols() {
            let col = cols.start + c;
            let (slot_bend, slot_axial) = (col % 2 == 0, col % 2 == 1);
            assert!(slot_bend || phi[(1, c)] == 0.0, "bend_y in column {col}");
            assert!(
                slot_axial || phi[(3, c)] == 0.0,
                "elongation in column {col}"
            );
            for row in [0, 2, 4, 5] {
                assert_eq!(phi[(row, c)], 0.0);
            }
        }
    }
}
