//! `Φ_s` at every site in the layout that multiplies it fastest: [`Stacked`] blocks where they
//! are tall (one product vectorizes down the sites), else [`SiteRows`] (one row per site and
//! component, four columns at a time). Both give the same products to rounding
//! (`the_site_products_equal_the_dense_basis_times_the_map`, on bases of either kind).

use super::site_rows::SiteRows;
use super::stacked::Stacked;
use gvs::lie::V6;
use gvs::strain::LinearBasis;

pub(super) enum BasisRows {
    Stacked(Stacked),
    Sites(SiteRows),
}

impl BasisRows {
    pub(super) fn of(basis: &LinearBasis) -> BasisRows {
        match Stacked::of(basis) {
            Some(st) => BasisRows::Stacked(st),
            None => BasisRows::Sites(SiteRows::of(basis)),
        }
    }

    /// Length of the `work` of the products below with up to `k` columns of `m` rows, on
    /// `n_sites` sites.
    pub(super) fn work_len(&self, m: usize, k: usize, n_sites: usize) -> usize {
        match self {
            BasisRows::Stacked(st) => st.y_len(k).max(n_sites),
            BasisRows::Sites(_) => SiteRows::work_len(m, k),
        }
    }

    /// `psi[s] = Φ_s x_0` and `out = Φ_s D` (`6 × r` column-major per site) for `X = [x_0 | D]`
    /// column-major `m × (1 + r)`, or `out` alone for `X = D` without `psi`.
    pub(super) fn products(
        &self,
        x: &[f64],
        m: usize,
        r: usize,
        psi: Option<&mut [V6]>,
        out: &mut [f64],
        work: &mut [f64],
    ) {
        match self {
            BasisRows::Stacked(st) => {
                let k = r + usize::from(psi.is_some());
                let y = &mut work[..st.y_len(k)];
                st.mul(x, m, k, y);
                st.scatter(y, r, psi, out);
            }
            BasisRows::Sites(rows) => rows.products(x, m, r, psi, out, work),
        }
    }

    /// `out[0][s] = Φ_s c`, `out[1][s] = Φ_s ċ`, `out[2][s] = Φ_s c̈` for `[c | ċ | c̈]`
    /// (column-major `m × 3`).
    pub(super) fn motion(&self, x: &[f64], m: usize, out: [&mut [V6]; 3], work: &mut [f64]) {
        match self {
            BasisRows::Stacked(st) => {
                let y = &mut work[..st.y_len(3)];
                st.mul(x, m, 3, y);
                st.scatter_motion(y, out);
            }
            BasisRows::Sites(rows) => rows.motion(x, m, out, work),
        }
    }

    /// `psi[s] = Φ_s x` at every site.
    pub(super) fn values(&self, x: &[f64], m: usize, psi: &mut [V6], work: &mut [f64]) {
        match self {
            BasisRows::Stacked(st) => {
                let y = &mut work[..st.y_len(1)];
                st.mul(x, m, 1, y);
                st.scatter_values(y, psi);
            }
            BasisRows::Sites(rows) => rows.values(x, psi),
        }
    }

    /// `g = Σ_s Φ_sᵀ w_s`.
    pub(super) fn mul_tr(&self, w: &[V6], g: &mut [f64], work: &mut [f64]) {
        match self {
            BasisRows::Stacked(st) => st.mul_tr(w, work, g),
            BasisRows::Sites(rows) => rows.mul_tr(w, g),
        }
    }
}
